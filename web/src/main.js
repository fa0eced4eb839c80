// Entry point of index.html: the dashboard with the standard panels and renderers (dashboard.js).

import { startDashboard } from "./dashboard.js";

startDashboard();

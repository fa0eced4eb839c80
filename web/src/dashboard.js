// The dashboard in a page: the device list (and, with discovery on, the discovered nodes) on the left,
// the selected device (#/<name>) on the right. index.html starts it with the standard panels and
// renderers (main.js); a page of its own starts it with its own registries (docs/dashboard.md
// "A page of your own"):
//
//   import { startDashboard } from "./src/dashboard.js";
//   import { standardRegistry } from "./src/std/standard.js";
//   import { standardPanels } from "./src/panels/standard.js";
//   startDashboard({ renderers: standardRegistry().register(myRenderer), panels: standardPanels().register(myPanel) });
//
// The page needs the elements index.html has: #device-list, #gateway-status, #device-view, .topbar.

import { h } from "./dom.js";
import { DeviceList } from "./device_list.js";
import { DeviceView } from "./device_view.js";
import { DiscoveredList } from "./discovered_list.js";
import { loadFeatures } from "./features.js";

/**
 * Starts the dashboard in this page (once).
 * @param {object} [options]
 * @param {import("./panels/registry.js").PanelRegistry} [options.panels]  the panels by object type
 *   (default panels/standard.js standardPanels())
 * @param {import("./std/registry.js").RendererRegistry} [options.renderers]  the renderers by value
 *   type (default std/standard.js standardRegistry())
 */
export function startDashboard({ panels = undefined, renderers = undefined } = {}) {
  const list = new DeviceList(document.getElementById("device-list"), document.getElementById("gateway-status"));
  const main = document.getElementById("device-view");
  let view = null;

  function route() {
    const name = decodeURIComponent(location.hash.replace(/^#\/?/, ""));
    if (view && view.name === name) return;
    view?.close();
    view = null;
    main.replaceChildren();
    list.setSelected(name || null);
    if (!name) {
      main.append(h("p", { class: "hint", text: "Choose a device on the left." }));
      return;
    }
    view = new DeviceView(main, name, list, { panels, renderers });
  }

  // Without a device in the address, open the first one once the list is known.
  list.addEventListener("update", (ev) => {
    if (!location.hash && ev.detail.length) location.replace(`#/${encodeURIComponent(ev.detail[0].name)}`);
  });
  window.addEventListener("hashchange", route);
  const discovered = new DiscoveredList(document.getElementById("device-list"));
  // A service added from the discovered list opens as the selected device.
  discovered.addEventListener("added", (ev) => {
    list.poll();
    if (ev.detail?.name) location.hash = `#/${encodeURIComponent(ev.detail.name)}`;
  });
  list.start();
  route();
  // The optional parts only when the gateway serves them (GET api/features, asked once): no polling of
  // routes that answer 404.
  loadFeatures().then((features) => {
    if (features.discovery) discovered.start();
    if (features.auth) showUser();
  });
}

// With logins on: who is logged in, and a way out.
async function showUser() {
  try {
    const r = await fetch("api/whoami", { headers: { Accept: "application/json" }, cache: "no-store" });
    if (!r.ok) return;
    const me = await r.json();
    if (!me.auth) return;
    const logout = h("button", { type: "button", id: "logout", text: "Log out" });
    logout.addEventListener("click", async () => {
      await fetch("api/logout", { method: "POST", cache: "no-store" }).catch(() => {});
      location.replace("login.html");
    });
    document.querySelector(".topbar").append(h("span", { class: "user-box" }, h("span", { id: "user-name", text: me.user }), logout));
  } catch { /* the gateway went away: the device list says so */ }
}

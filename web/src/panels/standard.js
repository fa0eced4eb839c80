// The panels of the standard object types, gathered: the device card (any object with a standard
// device_info property), the camera, robot, sensor (force/torque, vector, IMU, GPS), laser scanner,
// tool and light panels.

import { PanelRegistry } from "./registry.js";
import { deviceCardPanel } from "./device_card.js";
import { cameraPanel } from "./camera_panel.js";
import { robotPanel } from "./robot_panel.js";
// sensors and laser scanners
import { sensorPanel } from "./sensor_panel.js";
import { laserScannerPanel } from "./laser_scanner_panel.js";
import { imuPanel } from "./imu_panel.js";
import { gpsPanel } from "./gps_panel.js";
import { toolPanel } from "./tool_panel.js";
import { lightPanel } from "./light_panel.js";

/** A new registry holding the standard panels (add your own with register()). */
export function standardPanels() {
  return new PanelRegistry().register(deviceCardPanel, cameraPanel, robotPanel)
    // sensors, laser scanners
    .register(sensorPanel, laserScannerPanel, imuPanel, gpsPanel)
    // tools and lights
    .register(toolPanel, lightPanel);
}

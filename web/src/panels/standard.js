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
// joysticks, signals and the other standard device types (stdpanels-c)
import { joystickPanel } from "./joystick_panel.js";
import { signalPanel } from "./signal_panel.js";
import { servoPanel } from "./servo_panel.js";
import { actuatorPanel } from "./actuator_panel.js";
import { clockPanel } from "./clock_panel.js";
import { eventLogPanel } from "./event_log_panel.js";
import { billboardPanel } from "./billboard_panel.js";
import { resourcePanel } from "./resource_panel.js";
import { planningPanel } from "./planning_panel.js";
// stdpanels-d: point clouds, cameras beyond one, fiducials, object recognition
import { pointCloudPanel } from "./point_cloud_panel.js";
import { multiCameraPanel } from "./multicamera_panel.js";
import { imagePartCameraPanel } from "./image_part_camera_panel.js";
import { detectionsPanel } from "./detections_panel.js";

/** A new registry holding the standard panels (add your own with register()). */
export function standardPanels() {
  return new PanelRegistry().register(deviceCardPanel, cameraPanel, robotPanel)
    // sensors, laser scanners
    .register(sensorPanel, laserScannerPanel, imuPanel, gpsPanel)
    // tools and lights
    .register(toolPanel, lightPanel)
    // joysticks, signals and the other standard device types (stdpanels-c)
    .register(joystickPanel, signalPanel, servoPanel, actuatorPanel, clockPanel, eventLogPanel, billboardPanel, resourcePanel, planningPanel)
    // stdpanels-d: point clouds, cameras beyond one, fiducials, object recognition
    .register(pointCloudPanel, multiCameraPanel, imagePartCameraPanel, detectionsPanel);
}

// The renderers and field annotators of the standard types (com.robotraconteur.*), gathered from the
// modules that define them.

import { RendererRegistry } from "./registry.js";
import { TypeDescriber } from "./describe.js";
import { flagAnnotator, codeAnnotator } from "./enums.js";
import { unitsAnnotator } from "./units.js";
import { renderers as uuid } from "./uuid.js";
import { renderers as identifier } from "./identifier.js";
import { renderers as datetime } from "./datetime.js";
import { renderers as geometry } from "./geometry.js";
import { renderers as units } from "./units.js";
import { renderers as image } from "./image_renderers.js";
import { renderers as deviceInfo } from "./device_info.js";
import { renderers as datatype } from "./datatype.js";
// stdpanels-a: sensors, laser scans, point clouds
import { renderers as wrench } from "./wrench.js";
import { renderers as laserscan } from "./laserscan.js";
// stdpanels-c: joint trajectories, PID and parameter values
import { renderers as trajectory } from "./trajectory.js";
import { renderers as param } from "./param.js";
// stdpanels-d: point clouds
import { renderers as pointcloud } from "./pointcloud.js";

/** A new registry holding the standard renderers (add your own with register()). */
export function standardRegistry() {
  return new RendererRegistry().register(uuid, identifier, datetime, geometry, units, image, deviceInfo, datatype)
    // stdpanels-a: sensors, laser scans, point clouds
    .register(wrench, laserscan)
    // stdpanels-c: joint trajectories, PID and parameter values
    .register(trajectory, param)
    // stdpanels-d: point clouds
    .register(pointcloud);
}

/** The field annotators of the standard types: flag enums, enum codes in integer fields, units. */
export const STANDARD_ANNOTATORS = Object.freeze([flagAnnotator, codeAnnotator, unitsAnnotator]);

/** A TypeDescriber for one device's definitions (RobdefOutline) with the standard renderers. */
export function standardDescriber(outline, registry = standardRegistry()) {
  return new TypeDescriber(outline, registry, STANDARD_ANNOTATORS);
}

// Declarations of view3d.js (a three.js view of a robot from its RobotInfo), for the package's users:
// import { createRobotView3d } from "robotraconteur-wasm/robot/view3d.js" (needs the `three` package,
// a peer dependency, resolvable as "three" and "three/addons/...": a bundler or an import map).
import type { PoseValue } from "./kinematics.js";

export interface RobotView3d {
  el: HTMLElement;
  /** False when the RobotInfo cannot be drawn or WebGL is missing; `message` says why (shown in el). */
  ok: boolean;
  message: string | null;
  /** RobotState.joint_position (radians, metres) and optionally kin_chain_tcp; cheap at any rate. */
  update(q: ArrayLike<number> | null | undefined, reportedTcp?: PoseValue[] | null): void;
  /** Frees the WebGL context, geometries and materials and removes el. */
  dispose(): void;
}

/** Mounts the view in `parent` for a RobotInfo value. Never throws for a RobotInfo it cannot use. */
export function createRobotView3d(parent: HTMLElement, info: unknown, options?: { height?: number }): RobotView3d;

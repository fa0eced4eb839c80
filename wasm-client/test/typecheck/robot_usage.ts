// The robot modules as a TypeScript user of the package imports them ("robotraconteur-wasm/robot/*.js",
// declared by web/src/robot/*.d.ts): type-checked (tsc --noEmit --strict) by package_test.mjs.
import { chainModel, robotModel, forwardKinematics, poseDifference, type PoseValue } from "robotraconteur-wasm/robot/kinematics.js";
import { createRobotView3d, type RobotView3d } from "robotraconteur-wasm/robot/view3d.js";

export function show(info: unknown, q: Float64Array, reported: PoseValue[], parent: HTMLElement): string {
  const { chains, errors } = robotModel(info);
  const fk = forwardKinematics(chainModel(info, 0), q);
  const d = poseDifference(fk.tcp, reported[0]);
  const view: RobotView3d = createRobotView3d(parent, info, { height: 240 });
  if (view.ok) view.update(q, reported); else console.warn(view.message);
  view.dispose();
  return `${chains.length} ${errors.join()} ${fk.points.length} ${d.distance} ${d.angle} ${fk.joints[0]?.type}`;
}

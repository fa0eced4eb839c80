// The robot panel's 3D view (web/src/robot/view3d.js): reads robot_info once, loads three.js only
// then (pages without a robot never fetch it), and follows the robot_state wire (the connection
// shared with the panel and the wire card) to move the joints and show the pose the driver reports.
// A robot_info it cannot draw, or three.js failing to load, leaves a one-line message, never an error.

import { h, errorText } from "../dom.js";
import { followWire } from "../views/shared_wire.js";

/**
 * Mounts the 3D view at the end of `parent` for object proxy `obj` when it has `infoMember` (the
 * robot_info property) and `stateMember` (the robot_state wire). Returns { dispose() }.
 */
export function mountRobot3d(parent, obj, { infoMember, stateMember }) {
  const slot = h("div", { class: "robot-3d" });
  parent.append(slot);
  let view = null, follow = null, latest = null, disposed = false;
  const message = (text) => slot.replaceChildren(h("p", { class: "robot-view3d-message", text: `3D view: ${text}` }));

  if (!infoMember || !stateMember || stateMember.writeonly) {
    slot.hidden = true;
  } else {
    follow = followWire(obj, stateMember.name, {
      onValue: (s) => { latest = s; view?.update(s?.joint_position, s?.kin_chain_tcp); },
    });
    // the canvas's height is kept free while three.js loads, so nothing below jumps when it appears
    slot.dataset.loading = "true";
    Promise.all([obj[infoMember.name].get(), import("../robot/view3d.js")]).then(([info, { createRobotView3d }]) => {
      if (disposed) return;
      delete slot.dataset.loading;
      view = createRobotView3d(slot, info);
      if (latest) view.update(latest.joint_position, latest.kin_chain_tcp);
    }).catch((e) => { if (!disposed) { delete slot.dataset.loading; message(errorText(e)); } });
  }

  return {
    dispose() {
      disposed = true;
      follow?.dispose();
      view?.dispose();
      slot.remove();
    },
  };
}

// The robot panel's 3D view (web/src/robot/view3d.js): draws the robot_info the panel read (one read
// for both), loads three.js only then (pages without a robot never fetch it), and follows the
// robot_state wire (the subscription shared with the panel and the wire card) to move the joints and
// show the pose the driver reports.
// A robot_info it cannot draw, or three.js failing to load, leaves a one-line message, never an error.

import { h, errorText } from "../dom.js";

/**
 * Mounts the 3D view at the end of `parent` when the robot has robot_info (`info`: the panel's read of
 * it, a promise; null without the property) and `stateMember` (the robot_state wire), followed through
 * `live` (views/live_object.js). Returns { dispose() }.
 */
export function mountRobot3d(parent, { live, info, stateMember }) {
  const slot = h("div", { class: "robot-3d" });
  parent.append(slot);
  let view = null, follow = null, latest = null, disposed = false;
  const message = (text) => slot.replaceChildren(h("p", { class: "robot-view3d-message", text: `3D view: ${text}` }));

  if (!info || !stateMember || stateMember.writeonly) {
    slot.hidden = true;
  } else {
    follow = live.followWire(stateMember.name, {
      onValue: (s) => { latest = s; view?.update(s?.joint_position, s?.kin_chain_tcp); },
    });
    // the canvas's height is kept free while three.js loads, so nothing below jumps when it appears
    slot.dataset.loading = "true";
    Promise.all([info, import("../robot/view3d.js")]).then(([robotInfo, { createRobotView3d }]) => {
      if (disposed) return;
      delete slot.dataset.loading;
      view = createRobotView3d(slot, robotInfo);
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

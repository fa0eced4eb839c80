// The robot panel's jogging (panels/robot_panel.js): hold-to-jog of joints (the buttons of the joints
// table and the keyboard) and of the tool (Cartesian jog buttons), the jog speed, and the device lock
// taken while jogging when asked. Jogging is safe by construction (robot/jog_repeater.js): each call
// asks for 0.15 s of motion, repeated every 50 ms while held, and every way a hold can end (release,
// blur, hidden tab, page hide, lost session, stale state, mode change, halt) just stops sending, so the
// robot stops by itself (docs/dashboard.md).

import { h, errorText } from "../dom.js";
import { JogRepeater, JOG_TIMEOUT_S } from "../robot/jog_repeater.js";
import { jogVelocity } from "../robot/joints.js";
import { modeText, isStale } from "../robot/status.js";
import { mayLock } from "../robot/access.js";
import { jogKey, jogKeysText } from "../robot/hold.js";
import { HoldToRun } from "../hold/hold_to_run.js";
import { jointBindings } from "../hold/gamepad.js";
import { createGamepadControl, hasGamepadApi } from "./gamepad_control.js";
import { CARTESIAN_AXES, cartesianVelocity, isNotImplemented } from "../robot/cartesian.js";

/**
 * The jog controls of one robot panel. `robot` is the panel's shared state (robot_panel.js); `parts`
 * the elements it fills: { el (the panel), jogBox, lockBox, lockHolder, cartBox }.
 * Returns { tableButtons (the joints table's jog buttons go here), jointCommand(i, dir), button(list,
 * label, dataset, makeCommand), forget(list), build(), refresh(), release(reason), dispose() }.
 */
export function createRobotJog(robot, { el, jogBox, lockBox, lockHolder, cartBox }) {
  const { obj } = robot;
  let lockHeld = false, heldKey = null;
  let cartesianMissing = false;  // the driver answered jog_cartesian with NotImplementedError
  let gamepad = null;  // "jog with a gamepad" (panels/gamepad_control.js), once the user may jog
  const speed = h("input", { type: "range", min: "0.05", max: "1", step: "0.05", value: "0.25", name: "jog-speed" });
  const speedText = h("output", { class: "robot-speed" });
  const showSpeed = () => { speedText.textContent = `${Math.round(Number(speed.value) * 100)}% of the reduced velocity limit`; };
  speed.addEventListener("input", showSpeed);
  showSpeed();
  const lockCheck = h("input", { type: "checkbox", name: "jog-lock" });
  lockBox.append(h("label", {}, lockCheck, " take the device lock while jogging"), lockHolder);
  const releaseLock = () => {
    if (!lockHeld) return;
    lockHeld = false;
    Promise.resolve().then(() => obj.$monitorExit()).catch(() => {});
  };

  const repeater = new JogRepeater({
    send: (c) => (c.kind === "joint" ? obj.jog_joint(c.velocity, JOG_TIMEOUT_S, false) : obj.jog_cartesian(c.velocity, JOG_TIMEOUT_S, false)),
    onError: (e, c) => {
      if (robot.disposed) return;
      if (c.kind === "cartesian" && isNotImplemented(e)) {
        // the robdef has no capability for it: the first refused call tells, the buttons go
        cartesianMissing = true;
        buildCartesian(!jogBox.hidden);
        refresh();
        return;
      }
      robot.showError(`${c.kind === "joint" ? "jog_joint" : "jog_cartesian"}: ${errorText(e)}`);
    },
    onStop: (reason) => hold.stopped(reason),
  });
  // the page's end of every hold (hold/hold_to_run.js): pointer, keys, gamepad, blur, hidden, session
  const hold = new HoldToRun({
    motion: repeater,
    client: obj.$client,
    prepare: async () => {
      if (!lockCheck.checked || lockHeld) return true;
      try {
        await obj.$monitorEnter(2000);
        lockHeld = true;
        return true;
      } catch (e) {
        if (!robot.disposed) robot.showError(`lock: ${errorText(e)}`);
        return false;
      }
    },
    cancelled: releaseLock,
    onError: (e) => robot.showError(`jog: ${e.message}`),
    onStart: () => {
      robot.showError(null);
      el.dataset.jog = "on";
      el.dataset.jogHolds = String(Number(el.dataset.jogHolds ?? 0) + 1);  // for tests: a hold started
    },
    onStop: (reason) => {
      heldKey = null;
      releaseLock();
      el.dataset.jog = "off";
      el.dataset.jogStop = reason;
    },
  });
  const press = (makeCommand, source) => hold.press(makeCommand, source);
  const release = (reason) => { heldKey = null; hold.release(reason); };
  const jointCommand = (i, dir) => () => ({ kind: "joint", velocity: jogVelocity(robot.model, i, dir, Number(speed.value)) });

  // Keyboard shortcuts, only while the panel has focus and not while typing in a field.
  el.addEventListener("keydown", (ev) => {
    if (ev.target.closest?.("input, select, textarea") || ev.ctrlKey || ev.metaKey || ev.altKey) return;
    const k = jogKey(ev.key, robot.model.length);
    if (!k || !enabled()) return;
    ev.preventDefault();
    if (ev.repeat || heldKey === ev.key.toLowerCase()) return;
    heldKey = ev.key.toLowerCase();
    press(jointCommand(k.joint, k.direction), "key");
  });
  el.addEventListener("keyup", (ev) => { if (heldKey && ev.key.toLowerCase() === heldKey) release("keyup"); });
  el.addEventListener("focusout", (ev) => { if (heldKey && !el.contains(ev.relatedTarget)) release("blur"); });

  const enabled = () => robot.canJog() && !!robot.state && !isStale(robot.lastStateMs, Date.now())
    && modeText(robot.enums.mode, robot.state.command_mode) === "jog";
  // the jog buttons now on the page: the Cartesian ones and the joint table's (rebuilt with the table)
  const cartButtons = [], tableButtons = [];
  function button(list, label, dataset, makeCommand) {
    const b = hold.button(h("button", { type: "button", class: "small jog", text: label, dataset }), makeCommand);
    list.push(b);
    return b;
  }
  function refresh() {
    const on = enabled();
    const state = robot.state;
    const why = on ? "" : !state ? "no robot state" : isStale(robot.lastStateMs, Date.now()) ? "robot state is stale" : "set the command mode to jog";
    for (const b of [...cartButtons, ...tableButtons]) { b.disabled = !on; b.title = why; }
    if (!on && repeater.active) release("not jogging");
  }

  /** Shows the jog speed, the lock choice and the Cartesian buttons when the robot and the user may jog. */
  function build() {
    const jog = robot.canJog() && robot.model.length > 0;
    jogBox.hidden = !jog;
    lockBox.hidden = !jog || !mayLock(robot.access);  // the lock needs the roles' `lock` (docs/security.md)
    if (jog) {
      jogBox.replaceChildren(h("label", {}, "jog speed ", speed), speedText,
        h("span", { class: "hint", text: `hold a − / + button (keys ${robot.model.slice(0, 7).map((_, i) => jogKeysText(i)).join(", ")} while the panel has focus)` }));
      if (hasGamepadApi()) {
        gamepad ??= createGamepadControl(hold, {
          bindings: () => jointBindings(robot.model.length, jointCommand),
          press: (b) => { if (!enabled()) return false; press(b.command, "gamepad"); return true; },
        });
        jogBox.append(gamepad.el);
      }
    }
    buildCartesian(jog);
    return jog;
  }

  function buildCartesian(jog) {
    forget(cartButtons);
    const cart = jog && robot.caps.has("jog_command") && robot.may("jog_cartesian");
    cartBox.hidden = !cart;
    cartBox.dataset.missing = String(cartesianMissing);
    if (cart && cartesianMissing) {
      cartBox.replaceChildren(h("span", { class: "hint", text: "Cartesian jog: this driver does not implement jog_cartesian" }));
    } else cartBox.replaceChildren(...(cart ? [h("span", { class: "state-label", text: "Cartesian jog" }),
      ...CARTESIAN_AXES.flatMap((a) => [-1, 1].map((d) => button(cartButtons, `${a.label}${d > 0 ? "+" : "−"}`, { axis: a.id, dir: String(d) },
        () => ({ kind: "cartesian", velocity: cartesianVelocity(a.id, d, Number(speed.value)) }))))] : []));
  }

  /** The buttons in `list` leave the page (the joints table is rebuilt). */
  const forget = (list) => { hold.forgetButtons(list); list.length = 0; };

  return {
    tableButtons, jointCommand, button, forget, build, refresh, release,
    get shown() { return !jogBox.hidden; },
    dispose() { gamepad?.dispose(); hold.dispose(); },
  };
}

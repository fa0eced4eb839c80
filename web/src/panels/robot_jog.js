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
import { holdButton, jogKey, jogKeysText } from "../robot/hold.js";
import { CARTESIAN_AXES, cartesianVelocity, isNotImplemented } from "../robot/cartesian.js";

/**
 * The jog controls of one robot panel. `robot` is the panel's shared state (robot_panel.js); `parts`
 * the elements it fills: { el (the panel), jogBox, lockBox, lockHolder, cartBox }.
 * Returns { buttons (the joints table's jog buttons go here), jointCommand(i, dir), button(list, label,
 * dataset, makeCommand), build(), refresh(), release(reason), dispose() }.
 */
export function createRobotJog(robot, { el, jogBox, lockBox, lockHolder, cartBox }) {
  const { obj } = robot;
  let lockHeld = false, pressId = 0, heldKey = null;
  let cartesianMissing = false;  // the driver answered jog_cartesian with NotImplementedError
  const cleanups = [];
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
    onStop: (reason) => {
      if (reason === "replaced") return;  // another control took over the hold
      releaseLock();
      el.dataset.jog = "off";
      el.dataset.jogStop = reason;
      for (const b of el.querySelectorAll("button.held")) b.classList.remove("held");
    },
  });

  /** Starts a hold of `makeCommand()` (taking the lock first when asked); nothing when jogging is not possible. */
  async function press(makeCommand) {
    const id = ++pressId;
    let command;
    try {
      command = makeCommand();
    } catch (e) {
      robot.showError(`jog: ${e.message}`);
      return;
    }
    if (lockCheck.checked && !lockHeld) {
      try {
        await obj.$monitorEnter(2000);
        lockHeld = true;
      } catch (e) {
        if (!robot.disposed) robot.showError(`lock: ${errorText(e)}`);
        return;
      }
      if (id !== pressId || robot.disposed) { releaseLock(); return; }  // let go while the lock was taken
    }
    robot.showError(null);
    el.dataset.jog = "on";
    el.dataset.jogHolds = String(Number(el.dataset.jogHolds ?? 0) + 1);  // for tests: a hold started
    repeater.start(command);
  }
  const release = (reason) => { pressId++; heldKey = null; repeater.stop(reason); };
  const jointCommand = (i, dir) => () => ({ kind: "joint", velocity: jogVelocity(robot.model, i, dir, Number(speed.value)) });

  // Every way the page can lose the operator ends the hold.
  const onBlur = () => release("blur");
  const onHidden = () => { if (document.visibilityState === "hidden") release("hidden"); };
  window.addEventListener("blur", onBlur);
  window.addEventListener("pagehide", onBlur);
  document.addEventListener("visibilitychange", onHidden);
  cleanups.push(() => {
    window.removeEventListener("blur", onBlur);
    window.removeEventListener("pagehide", onBlur);
    document.removeEventListener("visibilitychange", onHidden);
  });
  const offClose = obj.$client?.onClose?.(() => release("session closed"));
  if (typeof offClose === "function") cleanups.push(offClose);

  // Keyboard shortcuts, only while the panel has focus and not while typing in a field.
  el.addEventListener("keydown", (ev) => {
    if (ev.target.closest?.("input, select, textarea") || ev.ctrlKey || ev.metaKey || ev.altKey) return;
    const k = jogKey(ev.key, robot.model.length);
    if (!k || !enabled()) return;
    ev.preventDefault();
    if (ev.repeat || heldKey === ev.key.toLowerCase()) return;
    heldKey = ev.key.toLowerCase();
    press(jointCommand(k.joint, k.direction));
  });
  el.addEventListener("keyup", (ev) => { if (heldKey && ev.key.toLowerCase() === heldKey) release("keyup"); });
  el.addEventListener("focusout", (ev) => { if (heldKey && !el.contains(ev.relatedTarget)) release("blur"); });

  const enabled = () => robot.canJog() && !!robot.state && !isStale(robot.lastStateMs, Date.now())
    && modeText(robot.enums.mode, robot.state.command_mode) === "jog";
  // the jog buttons now on the page: the Cartesian ones and the joint table's (rebuilt with the table)
  const cartButtons = [], tableButtons = [];
  function button(list, label, dataset, makeCommand) {
    const b = h("button", { type: "button", class: "small jog", text: label, dataset });
    holdButton(b, () => press(makeCommand), release);  // the listeners go with the button
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
    }
    buildCartesian(jog);
    return jog;
  }

  function buildCartesian(jog) {
    cartButtons.length = 0;
    const cart = jog && robot.caps.has("jog_command") && robot.may("jog_cartesian");
    cartBox.hidden = !cart;
    cartBox.dataset.missing = String(cartesianMissing);
    if (cart && cartesianMissing) {
      cartBox.replaceChildren(h("span", { class: "hint", text: "Cartesian jog: this driver does not implement jog_cartesian" }));
    } else cartBox.replaceChildren(...(cart ? [h("span", { class: "state-label", text: "Cartesian jog" }),
      ...CARTESIAN_AXES.flatMap((a) => [-1, 1].map((d) => button(cartButtons, `${a.label}${d > 0 ? "+" : "−"}`, { axis: a.id, dir: String(d) },
        () => ({ kind: "cartesian", velocity: cartesianVelocity(a.id, d, Number(speed.value)) }))))] : []));
  }

  return {
    tableButtons, jointCommand, button, build, refresh, release,
    get shown() { return !jogBox.hidden; },
    dispose() {
      release("dispose");
      for (const c of cleanups) c();
    },
  };
}

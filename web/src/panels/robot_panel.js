// The robot panel, for objects implementing com.robotraconteur.robotics.robot.Robot: an operator's
// view of its robot_state wire (command mode, operational mode, controller state, the state flags as
// coloured chips, stale when no state came for 1 s), its current_errors, a joint table named and
// bounded from its robot_info (position, limit bar warning near a limit, velocity, effort) with
// hold-to-jog buttons, Cartesian jog, a "move to" form (jog_freespace), Enable / Disable / Reset
// errors / Halt and the command-mode switch, the tool pose.
//
// Moving controls appear only once the gateway said this page's user may use their member
// (robot/access.js) and the robot's capabilities allow them. Jogging is safe by construction
// (robot/jog_repeater.js): each call asks for 0.15 s of motion, repeated every 50 ms while held, and
// every way a hold can end just stops sending, so the robot stops by itself (docs/dashboard.md).

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { formatPose } from "../std/geometry.js";
import { fieldText } from "../std/typed_text.js";
import { followWire } from "../views/shared_wire.js";
import { JogRepeater, JOG_TIMEOUT_S } from "../robot/jog_repeater.js";
import { jointModel, jointRows, jogVelocity, toDisplay, fromDisplay, displayUnit } from "../robot/joints.js";
import { flagChips, modeText, isStale, capabilitySet, STALE_MS } from "../robot/status.js";
import { fetchAccess, allows, mayLock } from "../robot/access.js";
import { holdButton, jogKey, jogKeysText } from "../robot/hold.js";
import { CARTESIAN_AXES, cartesianVelocity, isNotImplemented } from "../robot/cartesian.js";
import { locksText } from "../robot/lock_text.js";
import { formatFlags } from "../std/enums.js";
import { mountRobot3d } from "./robot_3d.js";

export const ROBOT = "com.robotraconteur.robotics.robot.Robot";
const RR_ROBOT = "com.robotraconteur.robotics.robot";
const ERRORS_POLL_MS = 2000;
// The command modes the switch offers, with the capability each needs (halt needs none).
const MODES = [["halt", null], ["jog", "jog_command"], ["position_command", "position_command"],
  ["velocity_command", "velocity_command"], ["trajectory", "trajectory_command"], ["homing", "homing_command"]];

export function createRobotPanel(parent, ctx) {
  const { obj, view } = ctx;
  const find = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const enumValues = (name) => view?.outline?.types?.get(name)?.values ?? [];
  const modeEnum = enumValues(`${RR_ROBOT}.RobotCommandMode`);
  const opEnum = enumValues(`${RR_ROBOT}.RobotOperationalMode`);
  const ctrlEnum = enumValues(`${RR_ROBOT}.RobotControllerState`);
  const flagEnum = enumValues(`${RR_ROBOT}.RobotStateFlags`);
  const capEnum = enumValues(`${RR_ROBOT}.RobotCapabilities`);
  const unitEnum = enumValues("com.robotraconteur.robotics.joints.JointPositionUnits");
  const cleanups = [];
  let disposed = false;

  const error = h("div", { class: "member-error robot-error", role: "alert", hidden: true });
  const showError = (text) => { error.textContent = text || ""; error.hidden = !text; };
  const staleBadge = h("span", { class: "badge robot-stale", dataset: { state: "closed" }, text: "stale", hidden: true });
  const summary = h("dl", { class: "robot-state-rows" });
  const errorsBox = h("ul", { class: "robot-current-errors", hidden: true });
  const controls = h("div", { class: "camera-controls robot-controls" });
  const lockBox = h("div", { class: "robot-lock", hidden: true });
  // the 3D view mounts here (panels/robot_3d.js), last: it appears only once three.js has loaded, and
  // above the jog buttons it would push them away from a pointer about to press one
  const view3dBox = h("div", { class: "robot-view3d-box" });
  const joints = h("table", { class: "robot-joints" });
  const jogBox = h("div", { class: "robot-jog", hidden: true });
  const cartBox = h("div", { class: "robot-cartesian", hidden: true });
  const moveForm = h("form", { class: "robot-move", hidden: true });
  const poses = h("div", { class: "robot-tcp" });
  const el = h("section", { class: "panel robot-panel", tabindex: "0", dataset: { panel: "robot", jog: "off" } },
    h("h3", {}, "Robot ", staleBadge), controls, lockBox, error, summary, errorsBox, jogBox, joints, cartBox, moveForm, poses, view3dBox);
  parent.append(el);

  // ---- what the user may do: the gateway's answer and the robot's capabilities ----
  let access = null;        // null until the gateway answered
  let caps = null;          // Set of RobotCapabilities names, null until robot_info was read
  let model = [];           // jointModel of robot_info
  const may = (member, op = "call") => !!(access && find(member, op === "write" ? "property" : "function") && allows(access, member, op));
  const canJog = () => caps?.has("jog_command") && may("jog_joint");

  // ---- jogging ----
  let state = null, lastStateMs = 0;
  let lockHeld = false, pressId = 0, heldKey = null;
  let cartesianMissing = false;  // the driver answered jog_cartesian with NotImplementedError
  const speed = h("input", { type: "range", min: "0.05", max: "1", step: "0.05", value: "0.25", name: "jog-speed" });
  const speedText = h("output", { class: "robot-speed" });
  const showSpeed = () => { speedText.textContent = `${Math.round(Number(speed.value) * 100)}% of the reduced velocity limit`; };
  speed.addEventListener("input", showSpeed);
  showSpeed();
  const lockCheck = h("input", { type: "checkbox", name: "jog-lock" });
  const lockHolder = h("span", { class: "robot-lock-holder" });
  lockBox.append(h("label", {}, lockCheck, " take the device lock while jogging"), lockHolder);
  const releaseLock = () => {
    if (!lockHeld) return;
    lockHeld = false;
    Promise.resolve().then(() => obj.$monitorExit()).catch(() => {});
  };
  const repeater = new JogRepeater({
    send: (c) => (c.kind === "joint" ? obj.jog_joint(c.velocity, JOG_TIMEOUT_S, false) : obj.jog_cartesian(c.velocity, JOG_TIMEOUT_S, false)),
    onError: (e, c) => {
      if (disposed) return;
      if (c.kind === "cartesian" && isNotImplemented(e)) {
        // the robdef has no capability for it: the first refused call tells, the buttons go
        cartesianMissing = true;
        buildCartesian(!jogBox.hidden);
        refreshJogEnabled();
        return;
      }
      showError(`${c.kind === "joint" ? "jog_joint" : "jog_cartesian"}: ${errorText(e)}`);
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
      showError(`jog: ${e.message}`);
      return;
    }
    if (lockCheck.checked && !lockHeld) {
      try {
        await obj.$monitorEnter(2000);
        lockHeld = true;
      } catch (e) {
        if (!disposed) showError(`lock: ${errorText(e)}`);
        return;
      }
      if (id !== pressId || disposed) { releaseLock(); return; }  // let go while the lock was taken
    }
    showError(null);
    el.dataset.jog = "on";
    el.dataset.jogHolds = String(Number(el.dataset.jogHolds ?? 0) + 1);  // for tests: a hold started
    repeater.start(command);
  }
  const release = (reason) => { pressId++; heldKey = null; repeater.stop(reason); };
  const jointCommand = (i, dir) => () => ({ kind: "joint", velocity: jogVelocity(model, i, dir, Number(speed.value)) });

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
    const k = jogKey(ev.key, model.length);
    if (!k || !jogEnabled()) return;
    ev.preventDefault();
    if (ev.repeat || heldKey === ev.key.toLowerCase()) return;
    heldKey = ev.key.toLowerCase();
    press(jointCommand(k.joint, k.direction));
  });
  el.addEventListener("keyup", (ev) => { if (heldKey && ev.key.toLowerCase() === heldKey) release("keyup"); });
  el.addEventListener("focusout", (ev) => { if (heldKey && !el.contains(ev.relatedTarget)) release("blur"); });

  const jogEnabled = () => canJog() && !!state && !isStale(lastStateMs, Date.now()) && modeText(modeEnum, state.command_mode) === "jog";
  // the jog buttons now on the page: the Cartesian ones and the joint table's (rebuilt with the table)
  const cartButtons = [], tableButtons = [];
  function jogButton(list, label, dataset, makeCommand) {
    const b = h("button", { type: "button", class: "small jog", text: label, dataset });
    holdButton(b, () => press(makeCommand), release);  // the listeners go with the button
    list.push(b);
    return b;
  }
  function refreshJogEnabled() {
    const on = jogEnabled();
    const why = on ? "" : !state ? "no robot state" : isStale(lastStateMs, Date.now()) ? "robot state is stale" : "set the command mode to jog";
    for (const b of [...cartButtons, ...tableButtons]) { b.disabled = !on; b.title = why; }
    if (!on && repeater.active) release("not jogging");
  }

  // ---- the controls that need access and capabilities ----
  function buildControls() {
    controls.replaceChildren();
    const action = (name, label, cap) => {
      if (!may(name) || (cap && !caps?.has(cap))) return;
      const b = h("button", { type: "button", class: "small", text: label, dataset: { action: name }, onclick: async () => {
        if (name === "halt") release("halt");
        b.disabled = true;
        try {
          await obj[name]();
          if (!disposed) showError(null);
        } catch (e) {
          if (!disposed) showError(`${name}: ${errorText(e)}`);
        } finally {
          b.disabled = false;
        }
      } });
      controls.append(b);
    };
    action("enable", "Enable", "software_enable");
    action("disable", "Disable", "software_enable");
    action("reset_errors", "Reset errors", "software_reset_errors");
    action("halt", "Halt", null);
    if (may("command_mode", "write") && modeEnum.length) {
      const select = h("select", { name: "command-mode" },
        ...MODES.filter(([, cap]) => !cap || caps?.has(cap)).map(([m]) => h("option", { value: m, text: m })));
      const set = h("button", { type: "button", class: "small", text: "Set mode", dataset: { action: "command_mode" }, onclick: async () => {
        const target = modeEnum.find((e) => e.name === select.value)?.value;
        set.disabled = true;
        release("mode change");
        try {
          // the abstract robot takes a new mode only from halt
          const now = await obj.command_mode.get();
          if (Number(now) !== target && modeText(modeEnum, now) !== "halt" && select.value !== "halt") await obj.command_mode.set(modeEnum.find((e) => e.name === "halt").value);
          await obj.command_mode.set(target);
          if (!disposed) showError(null);
        } catch (e) {
          if (!disposed) showError(`command_mode: ${errorText(e)}`);
        } finally {
          set.disabled = false;
        }
      } });
      controls.append(h("label", { class: "robot-mode" }, "command mode ", select), set);
    }
    buildJog();
  }

  function buildJog() {
    const jog = canJog() && model.length > 0;
    jogBox.hidden = !jog;
    lockBox.hidden = !jog || !mayLock(access);  // the lock needs the roles' `lock` (docs/security.md)
    if (jog) {
      jogBox.replaceChildren(h("label", {}, "jog speed ", speed), speedText,
        h("span", { class: "hint", text: `hold a − / + button (keys ${model.slice(0, 7).map((_, i) => jogKeysText(i)).join(", ")} while the panel has focus)` }));
    }
    buildCartesian(jog);
    buildMoveForm(jog && may("jog_freespace"));
    renderJoints(true);
    refreshJogEnabled();
  }

  function buildCartesian(jog) {
    cartButtons.length = 0;
    const cart = jog && caps.has("jog_command") && may("jog_cartesian");
    cartBox.hidden = !cart;
    cartBox.dataset.missing = String(cartesianMissing);
    if (cart && cartesianMissing) {
      cartBox.replaceChildren(h("span", { class: "hint", text: "Cartesian jog: this driver does not implement jog_cartesian" }));
    } else cartBox.replaceChildren(...(cart ? [h("span", { class: "state-label", text: "Cartesian jog" }),
      ...CARTESIAN_AXES.flatMap((a) => [-1, 1].map((d) => jogButton(cartButtons, `${a.label}${d > 0 ? "+" : "−"}`, { axis: a.id, dir: String(d) },
        () => ({ kind: "cartesian", velocity: cartesianVelocity(a.id, d, Number(speed.value)) }))))] : []));
  }

  function buildMoveForm(show) {
    moveForm.hidden = !show;
    if (!show) { moveForm.replaceChildren(); return; }
    const inputs = model.map((j) => h("input", { type: "number", step: "any", required: true, name: j.name, "aria-label": `${j.name} (${displayUnit(j.units)})` }));
    const fraction = h("input", { type: "number", min: "1", max: "100", step: "1", value: "10", name: "max-velocity" });
    const fill = h("button", { type: "button", class: "small", text: "Current", onclick: () => {
      const q = state?.joint_position;
      if (q) inputs.forEach((inp, i) => { inp.value = String(Number(toDisplay(Number(q[i]), model[i].units).toFixed(4))); });
    } });
    const go = h("button", { type: "submit", class: "small", text: "Move to", dataset: { action: "jog_freespace" } });
    moveForm.replaceChildren(h("span", { class: "state-label", text: "move to" }),
      ...model.map((j, i) => h("label", {}, `${j.name} `, inputs[i], ` ${displayUnit(j.units)}`)),
      h("label", {}, "max velocity ", fraction, " % of limit"), fill, go);
    moveForm.onsubmit = async (ev) => {
      ev.preventDefault();
      const q = inputs.map((inp, i) => fromDisplay(Number(inp.value), model[i].units));
      const f = Number(fraction.value) / 100;
      if (q.some((x) => !Number.isFinite(x)) || !(f > 0 && f <= 1)) { showError("move to: every joint needs a number, max velocity 1..100 %"); return; }
      go.disabled = true;
      try {
        // wait true: the call lasts as long as the move, so the gateway's hold on the robot's motion (one
        // client at a time, docs/security.md "Motion safety") ends with it, not with this page.
        await obj.jog_freespace(Float64Array.from(q), Float64Array.from(model, (j) => f * j.reducedVelocity), true);
        if (!disposed) showError(null);
      } catch (e) {
        if (!disposed) showError(`jog_freespace: ${errorText(e)}`);
      } finally {
        go.disabled = false;
      }
    };
  }

  // ---- the state ----
  function renderJoints(rebuild) {
    const rows = jointRows(state ?? { joint_position: new Float64Array(model.length) }, model);
    const jog = !jogBox.hidden;
    if (rebuild || joints.tBodies[0]?.rows.length !== rows.length) {
      if (tableButtons.some((b) => b.classList.contains("held"))) release("table rebuilt");
      tableButtons.length = 0;
      joints.replaceChildren(
        h("thead", {}, h("tr", {}, ...["joint", "position", "limits", "velocity", "effort", jog ? "jog" : ""].map((t) => h("th", { text: t })))),
        h("tbody", {}, ...rows.map((r, i) => h("tr", { dataset: { joint: r.name } },
          h("td", { class: "joint-name", text: r.name }), h("td", { class: "joint-position" }),
          h("td", { class: "joint-limits" }, h("span", { class: "limit-bar" }, h("span", { class: "limit-mark" }))),
          h("td", { class: "joint-velocity" }), h("td", { class: "joint-effort" }),
          h("td", { class: "joint-jog" }, ...(jog ? [jogButton(tableButtons, "−", { joint: r.name, dir: "-1" }, jointCommand(i, -1)),
            jogButton(tableButtons, "+", { joint: r.name, dir: "1" }, jointCommand(i, 1))] : []))))));
    }
    if (!state) return;
    Array.from(joints.tBodies[0].rows).forEach((tr, i) => {
      const r = rows[i];
      tr.cells[1].textContent = r.text;
      const mark = tr.cells[2].firstChild.firstChild;
      tr.cells[2].firstChild.hidden = r.fraction === null;
      if (r.fraction !== null) mark.style.left = `${(r.fraction * 100).toFixed(1)}%`;
      tr.dataset.near = r.near ?? "";
      tr.cells[2].title = r.near ? `near the ${r.near} limit (${model[i].lower} … ${model[i].upper})` : "";
      tr.cells[3].textContent = r.velocity;
      tr.cells[4].textContent = r.effort;
    });
  }

  let follow = null, frame = 0;
  const stateMember = find("robot_state", "wire");
  const stateType = stateMember ? describeMember(view, obj, stateMember)?.type : null;
  function draw() {
    frame = 0;
    const s = state;
    if (!s || disposed) return;
    const dd = (key, ...content) => h("dd", { dataset: { row: key } }, ...content);
    const rows = [];
    const tsField = stateType.fields.find((f) => f.name === "ts");
    if (tsField && s.ts !== undefined) rows.push(["time", dd("ts", fieldText(s, tsField, stateType, view?.text))]);
    rows.push(["command mode", dd("command_mode", modeText(modeEnum, s.command_mode))]);
    rows.push(["operational mode", dd("operational_mode", modeText(opEnum, s.operational_mode))]);
    rows.push(["controller state", dd("controller_state", modeText(ctrlEnum, s.controller_state))]);
    const chips = flagChips(flagEnum, s.robot_state_flags ?? 0);
    rows.push(["flags", dd("robot_state_flags", ...(chips.length ? chips.map((c) => h("span", { class: `chip chip-${c.tone}`, text: c.name, dataset: { flag: c.name } })) : ["none"]))]);
    summary.replaceChildren(...rows.flatMap(([label, d]) => [h("dt", { text: label }), d]));
    el.dataset.flags = formatFlags(flagEnum, s.robot_state_flags ?? 0);
    renderJoints(false);
    const tcp = Array.isArray(s.kin_chain_tcp) ? s.kin_chain_tcp : s.kin_chain_tcp?.length ? Array.from(s.kin_chain_tcp) : [];
    poses.replaceChildren(...tcp.map((p, i) => h("div", { class: "robot-tool", dataset: { chain: String(i) } },
      `${tcp.length > 1 ? `tool ${i}` : "tool"}: ${formatPose(p) ?? "(invalid pose)"}`)));
    refreshJogEnabled();
  }
  if (stateMember && stateType?.fields && !stateMember.writeonly) {
    // shared with the robot_state card below (one connection per wire), reconnected after a close
    follow = followWire(obj, stateMember.name, {
      onValue: (v) => { state = v; lastStateMs = Date.now(); markStale(); if (!frame) frame = requestAnimationFrame(draw); },
      onError: (e) => {
        if (disposed) return;
        if (e) { showError(`robot_state: ${errorText(e)}`); release("robot_state closed"); }
        else if (error.textContent.startsWith("robot_state:")) showError(null);
      },
    });
  }
  function markStale() {
    const stale = isStale(lastStateMs, Date.now());
    if (String(stale) === el.dataset.stale) return;
    el.dataset.stale = String(stale);
    staleBadge.hidden = !stale;
    staleBadge.textContent = lastStateMs ? `stale: no robot_state for over ${STALE_MS / 1000} s` : "no robot_state yet";
    refreshJogEnabled();
  }
  const staleTimer = setInterval(markStale, 250);
  cleanups.push(() => clearInterval(staleTimer));
  markStale();

  // current_errors (a property, nolock): read every 2 s while the panel is shown
  if (find("current_errors", "property")) {
    let busy = false;
    const readErrors = async () => {
      if (busy || disposed) return;
      busy = true;
      try {
        const list = await obj.current_errors.get();
        const items = Array.isArray(list) ? list : list ? Array.from(list.values?.() ?? []) : [];
        errorsBox.replaceChildren(...items.map((m) => h("li", { text: [m?.title, m?.message].filter(Boolean).join(": ") || "(error without text)" })));
        errorsBox.hidden = !items.length;
      } catch {
        errorsBox.hidden = true;  // a driver without current_errors (or not allowed to read it)
      } finally {
        busy = false;
      }
    };
    const t = setInterval(readErrors, ERRORS_POLL_MS);
    cleanups.push(() => clearInterval(t));
    readErrors();
  }

  // the locks the gateway reports for this device
  const showLocks = () => {
    const d = ctx.devices?.device?.(ctx.device);
    const text = locksText(d?.locks);
    lockHolder.textContent = text ? ` (${text})` : "";
    el.dataset.locks = text;
  };
  if (ctx.devices?.addEventListener) {
    ctx.devices.addEventListener("update", showLocks);
    cleanups.push(() => ctx.devices.removeEventListener("update", showLocks));
  }
  showLocks();

  // robot_info and access, then the controls that need them
  const infoRead = find("robot_info", "property")
    ? obj.robot_info.get().then((info) => {
      model = jointModel(info, unitEnum);
      caps = capabilitySet(capEnum, info?.robot_capabilities);
    }).catch((e) => { caps = new Set(); if (!disposed) showError(`robot_info: ${errorText(e)}`); })
    : Promise.resolve().then(() => { caps = new Set(); });
  const accessRead = ctx.device
    ? fetchAccess(ctx.device, ctx.session?.username ?? null).then((a) => { access = a; })
      .catch((e) => { access = null; if (!disposed) showError(`${e.message}: no controls`); })
    : Promise.resolve().then(() => { access = { members: null }; });
  Promise.all([infoRead, accessRead]).then(() => {
    if (disposed) return;
    el.dataset.access = access ? (access.members === null ? "all" : "checked") : "none";
    buildControls();
    el.dataset.ready = "true";
  });
  renderJoints(true);

  // ---- 3D view of the robot from its robot_info (web/src/panels/robot_3d.js, web/src/robot/view3d.js) ----
  const view3d = mountRobot3d(view3dBox, obj, { infoMember: find("robot_info", "property"), stateMember });
  // ---- end of the 3D view ----

  return {
    el,
    /** Ends any hold now (for tests and the page). */
    stopJog: (reason = "stopped") => release(reason),
    dispose() {
      disposed = true;
      release("dispose");
      view3d.dispose();
      if (frame) cancelAnimationFrame(frame);
      follow?.dispose();
      for (const c of cleanups) c();
      el.remove();
    },
  };
}

export const robotPanel = { name: "robot", order: 20, types: [ROBOT], create: createRobotPanel };

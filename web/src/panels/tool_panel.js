// The tool panel, for objects implementing com.robotraconteur.robotics.tool.Tool (grippers, vacuum
// tools): an operator's view and controls, from parts with one job each that share one state (`tool`
// below: the enums, tool_info read once, the user's access, the newest tool_state):
//   tool_status.js    tool_state as position, command, flag chips and sensor values; stale badge; tool_info rows
//   tool_controls.js  Enable / Disable / Reset errors / Halt, hold-to-run Open / Close / Home / move to
// Its pure logic is in web/src/tool/. A Tool without a tool_state wire of the standard layout gets a
// line saying so, and the generic member view below shows its members (docs/dashboard.md).

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { capabilitySet } from "../robot/status.js";
import { fetchAccess, allows } from "../robot/access.js";
import { createToolStatus } from "./tool_status.js";
import { createToolControls } from "./tool_controls.js";

export const TOOL = "com.robotraconteur.robotics.tool.Tool";
const RR_TOOL = "com.robotraconteur.robotics.tool";
// the fields of ToolState the panel reads
const STATE_FIELDS = ["tool_state_flags", "position"];

export function createToolPanel(parent, ctx) {
  const { obj, view } = ctx;
  const find = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const enumValues = (name) => view?.outline?.types?.get(name)?.values ?? [];

  const error = h("div", { class: "member-error tool-error", role: "alert", hidden: true });
  const staleBadge = h("span", { class: "badge tool-stale", dataset: { state: "closed" }, text: "stale", hidden: true });
  const summary = h("dl", { class: "robot-state-rows tool-state-rows" });
  const controls = h("div", { class: "camera-controls tool-controls" });
  const moveBox = h("div", { class: "robot-move tool-move", hidden: true });
  const infoRows = h("dl", { class: "camera-info-rows tool-info", hidden: true });
  const el = h("section", { class: "panel tool-panel", dataset: { panel: "tool", hold: "off" } },
    h("h3", {}, "Tool ", staleBadge), controls, moveBox, error, summary, infoRows);
  parent.append(el);

  const stateMember = find("tool_state", "wire");
  const stateType = stateMember && !stateMember.writeonly ? describeMember(view, obj, stateMember)?.type : null;
  const fieldNames = new Set((stateType?.fields || []).map((f) => f.name));
  if (!stateType?.fields || STATE_FIELDS.some((f) => !fieldNames.has(f))) {
    // another layout (an older standard release, a missing member): the member view shows it plainly
    el.dataset.fallback = "true";
    summary.replaceChildren(h("span", { class: "hint", text: `this tool has no tool_state wire of the standard layout: its members are shown below` }));
    return { el, dispose() { el.remove(); } };
  }

  /** What the parts share. */
  const tool = {
    obj, view, find,
    enums: {
      flag: enumValues(`${RR_TOOL}.ToolStateFlags`),
      cap: enumValues(`${RR_TOOL}.ToolCapabilities`),
      type: enumValues(`${RR_TOOL}.ToolTypeCode`),
      sensor: enumValues("com.robotraconteur.sensor.SensorTypeCode"),
    },
    disposed: false,
    access: null,
    caps: new Set(),
    info: null,
    state: null,
    lastStateMs: 0,
    showError(text) { error.textContent = text || ""; error.hidden = !text; },
    may(member, op = "call") {
      return !!(tool.access && find(member, op === "write" ? "property" : "function") && allows(tool.access, member, op));
    },
  };

  const control = createToolControls(tool, { el, box: controls, moveBox });
  const status = createToolStatus(tool, { el, staleBadge, summary, infoRows }, stateType, () => control.refresh());

  let frame = 0;
  const draw = () => { frame = 0; if (!tool.disposed) { status.draw(); control.refresh(); } };
  const follow = ctx.live.followWire(stateMember.name, {
    onValue: (v) => { tool.state = v; tool.lastStateMs = Date.now(); status.markStale(); if (!frame) frame = requestAnimationFrame(draw); },
    onError: (e) => {
      if (tool.disposed) return;
      if (e) { tool.showError(`tool_state: ${errorText(e)}`); control.release("tool_state closed"); }
      else if (error.textContent.startsWith("tool_state:")) tool.showError(null);
    },
  });
  status.markStale();

  // tool_info (read once: capabilities, stroke, sensors) and the user's access, then the controls
  const infoMember = find("tool_info", "property");
  const infoType = infoMember ? describeMember(view, obj, infoMember)?.type : null;
  const infoRead = (infoMember && infoType?.fields ? obj.tool_info.get() : Promise.resolve(null)).then((i) => {
    tool.info = i;
    tool.caps = i ? capabilitySet(tool.enums.cap, i.tool_capabilities) : new Set();
    status.drawInfo(infoType);
  }, (e) => { if (!tool.disposed) tool.showError(`tool_info: ${errorText(e)}`); });
  const accessRead = ctx.device
    ? fetchAccess(ctx.device, ctx.session?.username ?? null).then((a) => { tool.access = a; })
      .catch((e) => { tool.access = null; if (!tool.disposed) tool.showError(`${e.message}: no controls`); })
    : Promise.resolve().then(() => { tool.access = { members: null }; });
  Promise.all([infoRead, accessRead]).then(() => {
    if (tool.disposed) return;
    el.dataset.access = tool.access ? (tool.access.members === null ? "all" : "checked") : "none";
    control.build();
    if (tool.state) status.draw();
    el.dataset.ready = "true";
  });

  return {
    el,
    /** Ends any hold now (for tests and the page). */
    stopHold: (reason = "stopped") => control.release(reason),
    dispose() {
      tool.disposed = true;
      control.dispose();
      if (frame) cancelAnimationFrame(frame);
      follow.dispose();
      status.dispose();
      el.remove();
    },
  };
}

export const toolPanel = { name: "tool", order: 20, types: [TOOL], create: createToolPanel };

// Small parts the sensor, laser scanner, IMU and GPS panels share: the error line of a panel, the
// gateway's access answer that decides their controls, the frame of a panel showing one state wire.

import { h, errorText } from "../dom.js";
import { fetchAccess } from "../robot/access.js";
import { describeMember } from "../views/context.js";

/**
 * The error line of a panel: { el, show(text|null), onMemberError(member) } where onMemberError gives
 * the onError handler of a followed wire or pipe (its error shown, cleared once it is open again).
 * `alive()` false after the panel is gone: nothing is shown then.
 */
export function errorLine(className, alive) {
  const el = h("div", { class: `member-error ${className}`, role: "alert", hidden: true });
  const show = (text) => { if (alive()) { el.textContent = text || ""; el.hidden = !text; } };
  const onMemberError = (member) => (e) => {
    if (e) show(`${member}: ${errorText(e)}`);
    else if (el.textContent.startsWith(`${member}:`)) show(null);
  };
  return { el, show, onMemberError };
}

/**
 * Once the gateway said what this page's user may do on the device (robot/access.js) and `ready` has
 * settled: `panelEl.dataset.access` ("all", "checked", or "none" when the answer failed: no control)
 * and then(access). Without a device name (a page of its own) everything is allowed.
 */
export function whenAccess(ctx, panelEl, ready, alive, then, showError) {
  const accessRead = ctx.device ? fetchAccess(ctx.device, ctx.session?.username ?? null) : Promise.resolve({ members: null });
  Promise.all([accessRead, ready]).then(([access]) => {
    if (!alive()) return;
    panelEl.dataset.access = access.members === null ? "all" : "checked";
    then(access);
  }, (e) => {
    if (!alive()) return;
    panelEl.dataset.access = "none";
    showError(`${e.message}: no controls`);
  });
}

/**
 * A panel that shows one standard state wire (the IMU's and the GPS's): its heading, error line, a
 * canvas beside rows of label and value, and the newest value drawn at most once per animation frame
 * (newest wins). Without a readable wire `spec.wire` of type `spec.typeName` holding `spec.fields`,
 * a one-line note and the generic view below. When the wire is there, `spec.setup({ type, row,
 * canvas, el })` (row(label) adds a row and gives its value element) returns `{ draw(value),
 * received?(value) }`: received sees every value and gives what to keep for the next draw.
 * Returns the panel's { el, dispose() }.
 */
export function stateWirePanel(parent, ctx, spec) {
  const { obj, view } = ctx;
  const m = (obj.$members || []).find((x) => x.name === spec.wire && x.kind === "wire" && !x.writeonly);
  const t = m ? describeMember(view, obj, m)?.type : null;
  const ok = t?.qualified === spec.typeName && spec.fields.every((n) => t.fields?.some((f) => f.name === n));
  let disposed = false, frame = 0, newest = null, count = 0, follow = null;
  const errors = errorLine(`${spec.panel}-error`, () => !disposed);
  const rows = h("dl", { class: `camera-info-rows ${spec.panel}-rows` });
  const canvas = h("canvas", { class: spec.canvasClass, width: spec.size, height: spec.size, "aria-label": spec.canvasLabel, style: "border: 1px solid #ddd" });
  const el = h("section", { class: `panel ${spec.panel}-panel`, dataset: { panel: spec.panel, samples: "0" } }, h("h3", { text: spec.title }), errors.el, h("div", { style: "display: flex; gap: 12px; align-items: flex-start" }, canvas, rows));
  parent.append(el);
  const row = (label) => { const dd = h("dd", { dataset: { row: label } }); rows.append(h("dt", { text: label }), dd); return dd; };
  if (!ok) {
    el.dataset.fallback = "true";
    canvas.hidden = true;
    const typeShort = spec.typeName.slice(spec.typeName.lastIndexOf(".") + 1);
    el.append(h("div", { class: "hint", text: `no ${spec.wire} wire of the standard ${typeShort} type on this device: its members are shown below` }));
  } else {
    const shown = spec.setup({ type: t, row, canvas, el });
    const draw = () => {
      frame = 0;
      if (disposed || !newest) return;
      shown.draw(newest);
      el.dataset.samples = String(count);
    };
    follow = ctx.live.followWire(m.name, {
      onValue: (v) => { newest = shown.received ? shown.received(v) : v; count++; if (!frame) frame = requestAnimationFrame(draw); },
      onError: errors.onMemberError(m.name),
    });
  }
  return {
    el,
    dispose() { disposed = true; follow?.dispose(); if (frame) cancelAnimationFrame(frame); el.remove(); },
  };
}

// The light panel, for com.robotraconteur.lighting Light, DimmableLight and ColorTunableLight: on/off,
// brightness (intensity, 0 to 100 %) and colour (ColorRGBA), with a swatch of what the light gives, and
// light_info's maximum lumens. The properties have no subscription: the panel reads them every second
// and after each change. Each control is there only when the light has the property and the gateway
// lets the page's user write it (robot/access.js); a light without on_off of type bool gets one line
// saying so and the generic member view below shows its members.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { fetchAccess, allows } from "../robot/access.js";
import { rgba, colorHex, hexColor, percentText, glowColor } from "../lighting/light_state.js";
import { StatusOrder } from "../status_order.js";

const L = "com.robotraconteur.lighting";
export const LIGHT_TYPES = [`${L}.Light`, `${L}.DimmableLight`, `${L}.ColorTunableLight`];
const POLL_MS = 1000;

export function createLightPanel(parent, ctx) {
  const { obj, view } = ctx;
  // a property the panel uses: there, and of the type the standard gives it (its descriptor's qualified type)
  const property = (name, qualifiedText) => {
    const m = (obj.$members || []).find((x) => x.name === name && x.kind === "property");
    return m && describeMember(view, obj, m)?.type?.qualifiedText === qualifiedText ? m : null;
  };
  const onOff = property("on_off", "bool");
  const intensity = property("intensity", "double");
  const color = property("color", "com.robotraconteur.color.ColorRGBA");
  const info = property("light_info", `${L}.LightInfo`);

  const error = h("div", { class: "member-error light-error", role: "alert", hidden: true });
  const showError = (t) => { error.textContent = t || ""; error.hidden = !t; };
  const swatch = h("div", { class: "light-swatch", role: "img", "aria-label": "light" });
  const rows = h("dl", { class: "camera-info-rows light-rows" });
  const controls = h("div", { class: "camera-controls light-controls" });
  const el = h("section", { class: "panel light-panel", dataset: { panel: "light" } }, h("h3", { text: "Light" }), swatch, rows, controls, error);
  parent.append(el);
  if (!onOff) {
    el.dataset.fallback = "true";
    rows.replaceChildren(h("span", { class: "hint", text: "this light has no on_off property of type bool: its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }

  let disposed = false, busy = false, timer = 0, lumens = null;
  const state = { on: false, intensity: undefined, color: undefined };
  const dd = (key, text) => h("dd", { dataset: { row: key }, text });
  function draw() {
    const list = [["on_off", "state", state.on ? "on" : "off"]];
    if (intensity) list.push(["intensity", "brightness", percentText(state.intensity)]);
    if (color) {
      const c = rgba(state.color);
      list.push(["color", "colour", c ? `${colorHex(c)} (r ${c.r.toFixed(3)}, g ${c.g.toFixed(3)}, b ${c.b.toFixed(3)}, a ${c.a.toFixed(3)})` : ""]);
    }
    if (lumens !== null) list.push(["max_lumens", "maximum", `${lumens} lm`]);
    rows.replaceChildren(...list.flatMap(([key, label, text]) => [h("dt", { text: label }), dd(key, text)]));
    swatch.style.background = glowColor(state);
    el.dataset.on = String(state.on);
    syncControls();
  }
  // a read that overlapped a write may hold the values from before it: StatusOrder drops it, and the
  // write's own read (which does not wait for a poll in flight) shows the result
  const order = new StatusOrder();
  async function read(afterWrite = false) {
    if ((busy && !afterWrite) || disposed) return;
    const ticket = order.beginPoll();
    if (!ticket) return;
    busy = true;
    try {
      const on = !!(await obj.on_off.get());
      const level = intensity ? Number(await obj.intensity.get()) : undefined;
      const c = color ? await obj.color.get() : undefined;
      if (disposed || !order.accept(ticket)) return;
      state.on = on;
      if (intensity) state.intensity = level;
      if (color) state.color = c;
      draw();
      el.dataset.reads = String(Number(el.dataset.reads ?? 0) + 1);
    } catch (e) {
      if (!disposed && order.accept(ticket)) showError(`read: ${errorText(e)}`);
    } finally {
      busy = false;
    }
  }
  async function write(member, value) {
    order.beginChange();
    try {
      await obj[member].set(value);
      if (!disposed) showError(null);
    } catch (e) {
      if (!disposed) showError(`${member}: ${errorText(e)}`);
    } finally {
      order.endChange();
    }
    await read(true);
  }

  // controls, once the gateway said what this user may write
  let toggle = null, slider = null, picker = null;
  function syncControls() {
    if (toggle) toggle.textContent = state.on ? "Turn off" : "Turn on";
    if (slider && document.activeElement !== slider && Number.isFinite(state.intensity)) slider.value = String(state.intensity);
    if (picker && document.activeElement !== picker && colorHex(state.color)) picker.value = colorHex(state.color);
  }
  const accessRead = ctx.device ? fetchAccess(ctx.device, ctx.session?.username ?? null) : Promise.resolve({ members: null });
  accessRead.then((access) => {
    if (disposed) return;
    el.dataset.access = access.members === null ? "all" : "checked";
    const may = (m) => allows(access, m, "write");
    if (may("on_off")) toggle = h("button", { type: "button", class: "small", dataset: { action: "on_off" }, onclick: () => write("on_off", !state.on) });
    if (intensity && may("intensity")) {
      slider = h("input", { type: "range", name: "light-intensity", min: "0", max: "1", step: "0.01", "aria-label": "brightness" });
      slider.addEventListener("change", () => write("intensity", Number(slider.value)));
    }
    if (color && may("color")) {
      picker = h("input", { type: "color", name: "light-color", "aria-label": "colour" });
      picker.addEventListener("change", () => { const c = hexColor(picker.value, rgba(state.color)?.a ?? 1); if (c) write("color", c); });
    }
    controls.replaceChildren(...[toggle, slider && h("label", {}, "brightness ", slider), picker && h("label", {}, "colour ", picker)].filter(Boolean));
    syncControls();
    el.dataset.ready = "true";
  }, (e) => { if (!disposed) showError(`${e.message}: no controls`); el.dataset.ready = "true"; });

  if (info) obj.light_info.get().then((i) => { lumens = Number.isFinite(Number(i?.max_lumens)) ? Number(i.max_lumens) : null; if (!disposed) draw(); }, () => {});
  read();
  timer = setInterval(read, POLL_MS);
  return { el, dispose() { disposed = true; clearInterval(timer); el.remove(); } };
}

export const lightPanel = { name: "light", order: 20, types: LIGHT_TYPES, create: createLightPanel };

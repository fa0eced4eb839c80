// The camera panel, for objects implementing com.robotraconteur.imaging.Camera: the live picture of
// one of its streams (preview_stream first; frame_stream_compressed and frame_stream to choose),
// start and stop streaming, a captured frame (capture_frame, capture_frame_compressed), the state
// flags of its camera_state wire by name, and its capabilities, camera_info and param_info readable.
// Each part is there only when the device has the member with a type the page recognises; the
// generic member view below still shows every member.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { FrameView } from "../views/frame_view.js";
import { imageKind } from "../views/image_set.js";
import { PictureStream } from "../views/picture_stream.js";
import { typedText, fieldText, memberText } from "../std/typed_text.js";

export const CAMERA = "com.robotraconteur.imaging.Camera";
const STREAMS = ["preview_stream", "frame_stream_compressed", "frame_stream"];

/** Rows [{ label, text }] of a structure value: each field of descriptor `d` as readable text. */
export function structRows(value, d, textCtx) {
  if (!value || typeof value !== "object" || !d?.fields) return [];
  return d.fields.filter((f) => value[f.name] !== null && value[f.name] !== undefined && f.name !== "extended")
    .map((f) => ({ label: f.name, text: fieldText(value, f, d, textCtx) }));
}

export function createCameraPanel(parent, ctx) {
  const { obj, view } = ctx;
  const find = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const described = (m) => (m ? describeMember(view, obj, m) : null);
  const disposers = [];
  let disposed = false;

  const error = h("div", { class: "member-error camera-error", role: "alert", hidden: true });
  const showError = (text) => { error.textContent = text || ""; error.hidden = !text; };
  const fail = (what) => (e) => { if (!disposed) showError(`${what}: ${errorText(e)}`); };

  const state = h("output", { class: "camera-state" });
  const controls = h("div", { class: "camera-controls" });
  const liveBox = h("div", { class: "camera-live" });
  const captured = h("div", { class: "camera-capture", hidden: true }, h("div", { class: "hint", text: "captured" }));
  const info = h("div", { class: "camera-info" });
  const el = h("section", { class: "panel camera-panel", dataset: { panel: "camera" } },
    h("h3", { text: "Camera" }), state, controls, error, h("div", { class: "camera-views" }, liveBox, captured), info);
  parent.append(el);

  // live picture: one stream at a time
  const streams = STREAMS.map((n) => find(n, "pipe")).map((m) => [m, described(m)])
    .filter(([m, d]) => m && imageKind(d?.type));
  let current = null;
  const select = h("select", { "aria-label": "camera stream", class: "camera-stream" },
    ...streams.map(([m]) => h("option", { value: m.name, text: m.name })));
  function show(name) {
    current?.dispose();
    current = null;
    const [m, d] = streams.find(([x]) => x.name === name) || [];
    if (!m) return;
    current = new PictureStream(liveBox, {
      live: ctx.live, member: m.name, type: d.type, view, label: m.name,
      onError: (t) => { if (!disposed) showError(t); },
      onOpen: (open) => { el.dataset.streamOpen = open ? m.name : ""; },
    });
    current.el.dataset.stream = m.name;
    current.start();
  }
  if (streams.length) {
    select.addEventListener("change", () => show(select.value));
    controls.append(h("label", { class: "param" }, h("span", { text: "stream" }), select));
  }

  const call = (name, label, then) => {
    const m = find(name, "function");
    if (!m) return;
    const b = h("button", { type: "button", class: "small", text: label, dataset: { action: name }, onclick: async () => {
      b.disabled = true;
      try {
        const r = await obj[name]();
        if (disposed) return;
        showError(null);
        then?.(r, m);
      } catch (e) {
        fail(name)(e);
      } finally {
        b.disabled = false;
      }
    } });
    controls.append(b);
  };
  call("start_streaming", "Start streaming");
  call("stop_streaming", "Stop streaming");
  let captureView = null;
  const showCapture = (r, m) => {
    const type = described(m)?.type;
    if (!imageKind(type)) return;
    captured.hidden = false;
    captureView ??= new FrameView(captured, { context: view?.text, label: "captured frame" });
    captureView.el.dataset.capture = m.name;
    captureView.push(r, type.renderer);
  };
  call("capture_frame", "Capture frame", showCapture);
  call("capture_frame_compressed", "Capture compressed", showCapture);
  disposers.push(() => captureView?.dispose());

  // state flags from the camera_state wire
  const stateMember = find("camera_state", "wire");
  const stateDesc = described(stateMember)?.type;
  const flagsField = stateDesc?.fields?.find((f) => f.name === "state_flags");
  if (stateMember && !stateMember.writeonly) {
    // shared with the camera_state card below (one connection per wire), reconnected after a close
    const follow = ctx.live.followWire(stateMember.name, {
      onValue: (v) => {
        const text = flagsField ? fieldText(v, flagsField, stateDesc, view?.text) : typedText(v, stateDesc, view?.text);
        state.textContent = `state: ${text}`;
        state.dataset.flags = text;
      },
      onError: (e) => {
        if (e) fail("camera_state")(e);
        else if (!disposed && error.textContent.startsWith("camera_state:")) showError(null);
      },
    });
    disposers.push(() => follow.dispose());
  }

  // readable information: capabilities, camera_info, param_info
  const readInto = (name, render) => {
    const m = find(name, "property");
    if (!m || m.writeonly) return;
    const d = described(m);
    obj[name].get().then((v) => { if (!disposed) render(v, d); }).catch(fail(name));
  };
  const rows = h("dl", { class: "camera-info-rows" });
  info.append(rows);
  const addRows = (list, prefix = "") => rows.append(...list.flatMap((r) => [
    h("dt", { text: `${prefix}${r.label}` }), h("dd", { text: r.text, dataset: { row: `${prefix}${r.label}` } }),
  ]));
  readInto("capabilities", (v, d) => addRows([{ label: "capabilities", text: d ? memberText(v, d, view?.text) : String(v) }]));
  readInto("camera_info", (v, d) => {
    const t = d?.type;
    const device = t?.fields?.find((f) => f.name === "device_info");
    if (device && v?.device_info?.device) addRows([{ label: "device", text: typedText(v.device_info.device, device.type.fields?.find((f) => f.name === "device")?.type, view?.text) }]);
    const cal = t?.fields?.find((f) => f.name === "calibration");
    if (cal && v?.calibration) addRows(structRows(v.calibration, cal.type, view?.text), "calibration.");
    else if (t && !cal) addRows([{ label: "camera_info", text: typedText(v, t, view?.text) }]);
  });
  readInto("param_info", (v, d) => {
    const item = d?.type?.element;
    if (!Array.isArray(v) || !item?.fields) return;
    const col = (p, name) => {
      const f = item.fields.find((x) => x.name === name);
      return f && p?.[name] !== null && p?.[name] !== undefined ? fieldText(p, f, item, view?.text) : "";
    };
    const table = h("table", { class: "param-info" },
      h("thead", {}, h("tr", {}, ...["parameter", "type", "description"].map((t) => h("th", { text: t })))),
      h("tbody", {}, ...v.map((p) => h("tr", { dataset: { param: p?.parameter_identifier?.name ?? "" } },
        h("td", { text: col(p, "parameter_identifier") }), h("td", { text: col(p, "data_type") }),
        h("td", { text: col(p, "description").replace(/^"|"$/g, "") })))));
    info.append(h("div", { class: "hint", text: "param_info (getf_param / setf_param)" }), table);
  });

  if (streams.length) show(streams[0][0].name);
  return {
    el,
    dispose() {
      disposed = true;
      current?.dispose();
      for (const d of disposers) d();
      el.remove();
    },
  };
}

export const cameraPanel = { name: "camera", order: 20, types: [CAMERA], create: createCameraPanel };

// The MultiCamera panel, for com.robotraconteur.imaging.MultiCamera: a grid of the cameras' live pictures
// from one of its map pipes (preview_stream_all first; frame_stream_compressed_all and frame_stream_all to
// choose), each named from camera_names, and for users allowed to call them Trigger all (trigger_all) and
// Capture all (capture_frame_all, drawn in a second grid). Each camera is also an object of the cameras
// objref: opened below, it gets the camera panel. A rig whose pipes are not of the standard picture maps
// gets one line; the generic member view below shows its members.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { ImageSet, picturesOf, hasImages } from "../views/image_set.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { allows } from "../robot/access.js";

const GRID = "display: grid; grid-template-columns: repeat(auto-fill, minmax(200px, 1fr)); gap: 8px";
const STREAMS = ["preview_stream_all", "frame_stream_compressed_all", "frame_stream_all"];

export function createMultiCameraPanel(parent, ctx) {
  const { obj, view } = ctx;
  const find = (name, kind) => (obj.$members || []).find((m) => m.name === name && m.kind === kind) || null;
  const described = (m) => (m ? describeMember(view, obj, m)?.type : null);
  let disposed = false, names = new Map(), live = null, follow = null, captured = null;

  const errors = errorLine("multicamera-error", () => !disposed);
  const controls = h("div", { class: "camera-controls" });
  const grid = h("div", { class: "multicamera-grid" });
  const captureBox = h("div", { class: "multicamera-capture", hidden: true }, h("div", { class: "hint", text: "captured (capture_frame_all)" }));
  const el = h("section", { class: "panel multicamera-panel", dataset: { panel: "multicamera" } },
    h("h3", { text: "Cameras" }), controls, errors.el, grid, captureBox);
  parent.append(el);

  // each picture's heading: its key and the camera's name
  const label = (set) => {
    for (const [key, v] of set.views) {
      const head = v.box?.querySelector(".image-key");
      if (head && names.has(key)) head.textContent = `[${key}] ${names.get(key)}`;
      if (v.box) v.box.dataset.camera = names.get(key) ?? "";
    }
  };
  const namesMember = find("camera_names", "property");
  const namesRead = namesMember && !namesMember.writeonly
    ? obj.camera_names.get().then((v) => {
      if (disposed || !v) return;
      names = new Map([...(v instanceof Map ? v : Object.entries(v))].map(([k, n]) => [String(k), String(n)]));
      el.dataset.cameras = String(names.size);
      if (live) label(live);
    }, (e) => errors.show(`camera_names: ${errorText(e)}`))
    : Promise.resolve();

  const streams = STREAMS.map((n) => find(n, "pipe")).filter((m) => m && !m.writeonly && hasImages(described(m)));
  if (!streams.length) {
    el.dataset.fallback = "true";
    el.append(h("div", { class: "hint multicamera-fallback", text: "no camera picture pipe of the standard MultiCamera types on this device: its members are shown below" }));
  }
  const show = (name) => {
    follow?.close();
    live?.dispose();
    const m = streams.find((x) => x.name === name);
    if (!m) return;
    const d = described(m);
    live = new ImageSet(grid, { context: view?.text, label: m.name });
    live.el.style.cssText = GRID;
    el.dataset.stream = m.name;
    follow = ctx.live.followPipe(m.name, {
      onPacket: (v) => {
        if (disposed) return;
        live.push(picturesOf(v, d));
        label(live);
        el.dataset.pictures = String(live.views.size);
      },
      onOpen: (open) => { el.dataset.streamOpen = open ? m.name : ""; },
      onError: errors.onMemberError(m.name),
    });
  };
  if (streams.length > 1) {
    const select = h("select", { class: "camera-stream", "aria-label": "camera stream" }, ...streams.map((m) => h("option", { value: m.name, text: m.name })));
    select.addEventListener("change", () => show(select.value));
    controls.append(h("label", { class: "param" }, h("span", { text: "stream" }), select));
  }
  if (streams.length) show(streams[0].name);

  const button = (access, name, text, run) => {
    if (!find(name, "function") || !allows(access, name, "call")) return;
    const b = h("button", { type: "button", class: "small", text, dataset: { action: name }, onclick: async () => {
      b.disabled = true;
      try {
        await run();
        if (!disposed) errors.show(null);
      } catch (e) {
        if (!disposed) errors.show(`${name}: ${errorText(e)}`);
      } finally {
        b.disabled = false;
      }
    } });
    controls.append(b);
  };
  whenAccess(ctx, el, namesRead, () => !disposed, (access) => {
    button(access, "trigger_all", "Trigger all", async () => {
      await obj.trigger_all();
      el.dataset.triggered = String(Number(el.dataset.triggered || 0) + 1);
    });
    button(access, "capture_frame_all", "Capture all", async () => {
      const r = await obj.capture_frame_all();
      if (disposed) return;
      const d = described(find("capture_frame_all", "function"));
      captureBox.hidden = false;
      if (!captured) {
        captured = new ImageSet(captureBox, { context: view?.text, label: "captured" });
        captured.el.style.cssText = GRID;
      }
      captured.push(picturesOf(r, d));
      label(captured);
      el.dataset.captured = String(captured.views.size);
    });
  }, errors.show);

  return {
    el,
    dispose() {
      disposed = true;
      follow?.close();
      live?.dispose();
      captured?.dispose();
      el.remove();
    },
  };
}

export const multiCameraPanel = { name: "multicamera", order: 20, types: ["com.robotraconteur.imaging.MultiCamera"], create: createMultiCameraPanel };

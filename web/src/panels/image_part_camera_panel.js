// The ImagePartCamera panel, for com.robotraconteur.imaging.ImagePartCamera: the camera panel's parts
// (camera_panel.js: the live preview_stream, Start / Stop streaming, camera_state flags, capabilities,
// camera_info, param_info), with its capture_frame, a generator of ImageParts, put back into one Image
// and drawn (the camera panel's own Capture frame expects a whole Image and is replaced). The parts come
// in order (data_offset 0 first, each where the last ended, up to data_total_len); anything else is shown
// as an error and nothing drawn.

import { h, errorText } from "../dom.js";
import { createCameraPanel } from "./camera_panel.js";
import { FrameView } from "../views/frame_view.js";

const IMAGE = "com.robotraconteur.image";
const MAX_BYTES = 64 << 20;

/** Whole Image ({image_info, data}) of ImagePart values in order; throws with what is wrong. */
export function joinImageParts(parts) {
  let data = null, info = null, filled = 0;
  for (const p of parts) {
    const offset = Number(p?.data_offset), total = Number(p?.data_total_len), n = p?.data_part?.length ?? 0;
    if (!Number.isInteger(offset) || !Number.isInteger(total) || total <= 0 || total > MAX_BYTES || offset + n > total) {
      throw new Error(`part at ${p?.data_offset} of ${p?.data_total_len} does not fit`);
    }
    if (!data) {
      if (offset !== 0) throw new Error(`the first part starts at ${offset}, not 0`);
      data = new Uint8Array(total);
      info = p.image_info;
    }
    if (offset !== filled || total !== data.length) throw new Error(`part at ${offset} of ${total} after ${filled} of ${data.length} bytes`);
    data.set(p.data_part, offset);
    filled += n;
  }
  if (!data) throw new Error("no parts");
  if (filled !== data.length) throw new Error(`${filled} of ${data.length} bytes came`);
  return { image_info: info, data };
}

export function createImagePartCameraPanel(parent, ctx) {
  const panel = createCameraPanel(parent, ctx);
  const { obj, view } = ctx;
  const el = panel.el;
  el.dataset.panel = "image-part-camera";
  el.querySelector("h3").textContent = "Camera (image parts)";
  const capture = (obj.$members || []).find((m) => m.name === "capture_frame" && m.kind === "function" && m.generator);
  const old = el.querySelector('button[data-action="capture_frame"]');
  let frames = null, disposed = false;
  const error = el.querySelector(".camera-error");
  const showError = (t) => { if (!disposed && error) { error.textContent = t || ""; error.hidden = !t; } };
  if (old && capture) {
    const box = el.querySelector(".camera-capture");
    const b = h("button", { type: "button", class: "small", text: "Capture frame", dataset: { action: "capture_frame" }, onclick: async () => {
      b.disabled = true;
      try {
        const parts = [];
        for await (const p of await obj.capture_frame()) parts.push(p);
        if (disposed) return;
        const image = joinImageParts(parts);
        box.hidden = false;
        frames ??= new FrameView(box, { context: view?.text, label: "captured frame",
          renderer: view?.types?.describe(`${IMAGE}.Image`, IMAGE)?.renderer });
        frames.el.dataset.capture = "capture_frame";
        frames.el.dataset.parts = String(parts.length);
        frames.push(image);
        showError(null);
      } catch (e) {
        showError(`capture_frame: ${errorText(e)}`);
      } finally {
        b.disabled = false;
      }
    } });
    old.replaceWith(b);
  }
  return { el, dispose() { disposed = true; frames?.dispose(); panel.dispose(); } };
}

export const imagePartCameraPanel = {
  name: "image-part-camera", order: 20, types: ["com.robotraconteur.imaging.ImagePartCamera"], create: createImagePartCameraPanel,
};

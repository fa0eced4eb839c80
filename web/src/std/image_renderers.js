// Renderers of com.robotraconteur.image: Image (raw pixels, decoded by image_decode.js),
// CompressedImage (JPEG, PNG, ... by magic bytes, compressed_image.js) and their ImageInfo. Their
// picture hooks are what the dashboard draws with (registry.js "Renderer"): `check` refuses a bad
// frame from its header on the page, `image` / `compressed` decode it, `toWorker` hands it to the image
// Worker (image_worker.js) that does the same off the page.

import { decodeImage, checkImage } from "./image_decode.js";
import { checkCompressedImage } from "./compressed_image.js";
import { encodingNames } from "./image_encodings.js";

const I = "com.robotraconteur.image";

/** The device's ImageEncoding values from ctx (ctx.encodings, or ctx.outline's enum), or undefined. */
export function encodingsOf(ctx) {
  return ctx?.encodings ?? ctx?.outline?.types?.get(`${I}.ImageEncoding`)?.values;
}

function infoText(info, ctx) {
  const name = encodingNames(encodingsOf(ctx)).get(Number(info?.encoding)) ?? `encoding ${info?.encoding}`;
  return `${info?.width}×${info?.height} ${name}`;
}

function imageText(v, ctx) {
  const head = checkImage(v, encodingsOf(ctx));
  if (!head.ok) return `image: ${head.error.message}`;
  return `${head.width}×${head.height} ${head.encoding}, ${v.data.length} bytes`;
}

/** The frame as the image Worker takes it (image_worker.js): header numbers, the bytes, which kind. */
const workerFrame = (compressed) => (v, ctx) => {
  const info = v.image_info;
  return {
    image_info: { width: Number(info.width), height: Number(info.height), step: Number(info.step), encoding: info.encoding },
    data: v.data, compressed,
    options: { encodings: encodingsOf(ctx), depthRange: ctx?.depthRange, floatRange: ctx?.floatRange },
  };
};

function compressedText(v) {
  const c = checkCompressedImage(v);
  const size = v?.image_info?.width ? `${v.image_info.width}×${v.image_info.height} ` : "";
  if (!c.ok) return `compressed image: ${c.error.message}`;
  return `${size}${c.format.name}, ${v.data.length} bytes`;
}

export const renderers = [
  {
    type: `${I}.ImageInfo`,
    layout: { height: "uint32", width: "uint32", step: "uint32", encoding: `${I}.ImageEncoding` },
    text: infoText,
  },
  {
    type: `${I}.Image`, layout: { image_info: `${I}.ImageInfo`, data: "uint8[]" }, text: imageText,
    /** The header alone (no pixel read): checkImage's result. */
    check: (v, ctx) => checkImage(v, encodingsOf(ctx)),
    /** RGBA pixels or an error: decodeImage's result; ctx's depthRange, floatRange, out and imageOptions go to decodeImage. */
    image: (v, ctx) => decodeImage(v, {
      encodings: encodingsOf(ctx), depthRange: ctx?.depthRange, floatRange: ctx?.floatRange, out: ctx?.out, ...(ctx?.imageOptions || {}),
    }),
    toWorker: workerFrame(false),
  },
  {
    type: `${I}.CompressedImage`, layout: { image_info: `${I}.ImageInfo`, data: "uint8[]" }, text: compressedText,
    check: (v) => checkCompressedImage(v),
    /** The compressed format or an error: checkCompressedImage's result (the browser decodes the bytes). */
    compressed: (v) => checkCompressedImage(v),
    toWorker: workerFrame(true),
  },
];

/** The standard picture renderer for a frame: CompressedImage's when `compressed`, else Image's. */
export function standardPictureRenderer(compressed) {
  return renderers.find((r) => r.type === `${I}.${compressed ? "CompressedImage" : "Image"}`);
}

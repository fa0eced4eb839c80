// Renderers of com.robotraconteur.image: Image (raw pixels, decoded by image_decode.js),
// CompressedImage (JPEG, PNG, ... by magic bytes, compressed_image.js) and their ImageInfo.

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
    /** RGBA pixels or an error: decodeImage's result; ctx.imageOptions go to decodeImage. */
    image: (v, ctx) => decodeImage(v, { encodings: encodingsOf(ctx), ...(ctx?.imageOptions || {}) }),
  },
  {
    type: `${I}.CompressedImage`, layout: { image_info: `${I}.ImageInfo`, data: "uint8[]" }, text: compressedText,
    /** The compressed format or an error: checkCompressedImage's result (the browser decodes the bytes). */
    compressed: (v) => checkCompressedImage(v),
  },
];

// The standard types as a TypeScript user of the package imports them ("robotraconteur-wasm/std",
// declared by web/src/std/index.d.ts): type-checked (tsc --noEmit --strict) by package_test.mjs.
import { RobdefOutline, standardDescriber, typedText, decodeImage, imageToBitmap, FrameDecoder, formatUuid,
  typedNumericFields, sensorTimestamp, type TypeDescriptor, type BitmapResult } from "robotraconteur-wasm/std";

export async function show(definitions: Record<string, string>, frame: unknown, canvas: HTMLCanvasElement): Promise<string> {
  const types = standardDescriber(new RobdefOutline(definitions));
  const d: TypeDescriptor = types.describe("Image", "com.robotraconteur.imaging");
  const text: string = typedText(frame, d, { now: Date.now() });
  const decoded = decodeImage(frame);
  if (!decoded.ok) return `${decoded.error.code}: ${decoded.error.message}`;
  const r: BitmapResult = await imageToBitmap(frame, { compressed: false });
  if (r.ok) canvas.getContext("2d")?.drawImage(r.bitmap, 0, 0);
  const frames = new FrameDecoder({ onResult: (res) => { if (res.ok) res.bitmap.close(); } });
  frames.submit(frame, { compressed: true });
  const series: Array<[string, number, boolean]> = typedNumericFields(frame, d);
  const t = sensorTimestamp(frame, d)?.seconds ?? null;
  return `${text} ${formatUuid(frame) ?? ""} ${series.length} ${t} ${frames.stats.dropped}`;
}

// Frames of a stream decoded off the page's thread, the newest winning: at most one frame is being
// decoded (in image_worker.js, a module Worker) and at most one waits; a frame that arrives while one
// waits takes its place (the older one is dropped, counted in `stats.dropped`). A frame whose header
// is wrong (its renderer's `check`: for the standard images checkImage / checkCompressedImage, short
// data, unknown encoding, step below a row, no magic) is refused on the spot, before any pixel is read
// or sent anywhere: a flood of bad frames costs less than good ones.
//
//   import { FrameDecoder } from "./std/frame_decoder.js";
//   const dec = new FrameDecoder({ onResult: (r, meta) => r.ok ? draw(r.bitmap) : show(r.error) });
//   endpoint.onPacket((frame) => dec.submit(frame, { compressed: true }));
//   // or any picture type, through its renderer's hooks (registry.js "Renderer"):
//   dec.submit(value, { renderer: descriptor.renderer, context: { encodings } });
//
// Frames are decoded by their renderer (the standard Image or CompressedImage one unless `renderer` is
// given): off the page when the renderer hands frames to the image Worker (`toWorker`), else on the page
// (pictureToBitmap). The frame's data is transferred to the Worker (the value's Uint8Array is left
// empty) when it is a whole buffer of its own, as the client package gives it; otherwise (or with
// `transfer: false`) copied. Without Workers (or when the Worker cannot start) frames are decoded on
// the page, one at a time as above.

import { pictureToBitmap, isCompressedEncoding } from "./image_bitmap.js";
import { standardPictureRenderer } from "./image_renderers.js";

const WORKER_URL = new URL("./image_worker.js", import.meta.url);

export class FrameDecoder {
  /**
   * @param {object} opts
   * @param {(result: object, meta: object) => void} opts.onResult  each decoded frame or error, with
   *   the `meta` given to submit plus `seq` (submit order); results come in submit order
   * @param {Function|null} [opts.Worker]  the Worker class (default the global one; null: decode here)
   * @param {string|URL} [opts.workerUrl]  default image_worker.js beside this module
   * @param {(value: object, options: object) => Promise<object>} [opts.decode]  decoding on this
   *   thread (default: the frame's renderer's hooks, pictureToBitmap); `options` is the renderer
   *   context with `compressed` (whether the renderer's bytes are compressed) and `renderer`
   * @param {boolean} [opts.transfer]  false: never detach the caller's data (copy instead)
   */
  constructor(opts) {
    this.onResult = opts.onResult;
    this.decodeHere = opts.decode || ((value, options) => pictureToBitmap(value, options.renderer, options));
    this.transfer = opts.transfer !== false;
    this.stats = { submitted: 0, decoded: 0, failed: 0, dropped: 0, refused: 0 };
    this.seq = 0;
    this.busy = null;      // the job being decoded
    this.waiting = null;   // the newest job not started
    this.disposed = false;
    this.worker = null;
    const WorkerClass = opts.Worker === undefined ? globalThis.Worker : opts.Worker;
    if (typeof WorkerClass === "function") {
      try {
        this.worker = new WorkerClass(opts.workerUrl || WORKER_URL, { type: "module" });
        this.worker.onmessage = (ev) => this.finished(ev.data?.id, ev.data?.result);
        this.worker.onerror = (ev) => { ev?.preventDefault?.(); this.workerFailed(); };
        this.worker.onmessageerror = () => this.workerFailed();
      } catch {
        this.worker = null;
      }
    }
  }

  /** True when frames go to a Worker. */
  get inWorker() { return !!this.worker; }

  /**
   * Queues a frame. Returns the refusal result ({ok: false, error}) when its header is wrong (also
   * given to onResult), else null.
   * @param {object} value  a picture value: an Image or CompressedImage ({image_info, data}), or any
   *   value of `options.renderer`'s type
   * @param {object} [options]  renderer (the value's renderer; default: the standard Image or
   *   CompressedImage one, `compressed` or image_info.encoding tells which), context (what the
   *   renderer's hooks get; default these options: encodings, depthRange, floatRange)
   * @param {object} [meta]  anything; handed back with the result
   */
  submit(value, options = {}, meta = {}) {
    if (this.disposed) return null;
    const seq = ++this.seq;
    this.stats.submitted++;
    const renderer = options.renderer ?? standardPictureRenderer(options.compressed ?? isCompressedEncoding(value, options.encodings));
    const context = options.context ?? options;
    let head;
    try {
      head = renderer.check ? renderer.check(value, context) : { ok: true };
    } catch (e) {
      head = { ok: false, error: { code: "not_an_image", message: String(e?.message || e) } };
    }
    if (!head.ok) {
      this.stats.refused++;
      const refusal = { ok: false, error: head.error, format: head.format };
      try {
        this.onResult(refusal, { ...meta, seq });
      } catch (e) {
        console.error("FrameDecoder: onResult failed", e);
      }
      return refusal;
    }
    let work = null;
    try {
      work = this.worker && renderer.toWorker ? renderer.toWorker(value, context) : null;
    } catch {
      work = null;  // decoded on the page instead
    }
    const job = { seq, meta: { ...meta, seq }, value, work, options: { ...context, compressed: !!renderer.compressed, renderer } };
    if (this.busy) {
      if (this.waiting) this.stats.dropped++;
      this.waiting = job;
    } else {
      this.start(job);
    }
    return null;
  }

  start(job) {
    this.busy = job;
    if (this.worker && job.work) {
      const { data: d, ...rest } = job.work;
      const own = this.transfer && d.byteOffset === 0 && d.byteLength === d.buffer.byteLength;
      const data = own ? d : d.slice();
      job.sent = true;
      this.worker.postMessage({ id: job.seq, ...rest, data }, [data.buffer]);
      return;
    }
    Promise.resolve()
      .then(() => this.decodeHere(job.value, job.options))
      .catch((e) => ({ ok: false, error: { code: "decode_failed", message: String(e?.message || e) } }))
      .then((result) => this.finished(job.seq, result));
  }

  finished(id, result) {
    const job = this.busy;
    if (!job || job.seq !== id) return;
    this.busy = null;
    const r = result && typeof result === "object" ? result : { ok: false, error: { code: "decode_failed", message: "no result" } };
    if (this.disposed) {
      r.bitmap?.close?.();
      return;
    }
    if (r.ok) this.stats.decoded++; else this.stats.failed++;
    try {
      this.onResult(r, job.meta);
    } catch (e) {
      console.error("FrameDecoder: onResult failed", e);
    }
    const next = this.waiting;
    this.waiting = null;
    if (next) this.start(next);
  }

  /** The Worker could not run (e.g. its module did not load): decode here from now on. */
  workerFailed() {
    if (!this.worker) return;
    this.worker.terminate();
    this.worker = null;
    const job = this.busy;
    this.busy = null;
    if (job && !this.disposed) {
      // its data went to the Worker: that frame is lost; the next ones are decoded here
      this.stats.failed++;
      try {
        this.onResult({ ok: false, error: { code: "decode_failed", message: "the image Worker stopped; frames are decoded on the page from now on" } }, job.meta);
      } catch { /* the caller's handler: its own business */ }
    }
    const next = this.waiting;
    this.waiting = null;
    if (next) this.start(next);
  }

  dispose() {
    this.disposed = true;
    this.waiting = null;
    this.worker?.terminate();
    this.worker = null;
  }
}

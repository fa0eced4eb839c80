// Point clouds made drawable off the page's thread, the newest winning, as FrameDecoder does for
// pictures: at most one cloud is being coloured (in pointcloud_worker.js, a module Worker) and at most one
// waits; a cloud that arrives while one waits takes its place (the older is dropped, counted in
// `stats.dropped`, and was never copied out of its objects). The page's part is packCloud(): copying the
// points out of the client package's objects into flat arrays, done only for a cloud about to be sent;
// the Worker drops the holes, finds the bounds and colours every point (colorCloud). Without Workers (or
// when the Worker fails) colorCloud runs on the page, the same way.
//
//   const dec = new CloudDecoder({ onResult: (r, meta) => r.ok ? view.show(r) : show(r.error) });
//   endpoint.onPacket((d) => dec.submit({ cloud: d.point_cloud }, { mode: "auto" }, { seqno }));
//   // or a cloud already packed (CloudAssembler's whole clouds): dec.submit({ packed })

import { packCloud, colorCloud } from "./pointcloud.js";

const WORKER_URL = new URL("./pointcloud_worker.js", import.meta.url);

export class CloudDecoder {
  /**
   * @param {object} opts
   * @param {(result: object, meta: object) => void} opts.onResult  each drawable cloud (colorCloud's
   *   form, ok true, `ms` the colouring time, `packMs` the page's copying time) or { ok: false, error },
   *   with the submit's `meta` plus `seq`
   * @param {Function|null} [opts.Worker]  the Worker class (default the global one; null: colour here)
   * @param {string|URL} [opts.workerUrl]  default pointcloud_worker.js beside this module
   */
  constructor(opts) {
    this.onResult = opts.onResult;
    this.stats = { submitted: 0, decoded: 0, failed: 0, dropped: 0 };
    this.seq = 0;
    this.busy = null;
    this.waiting = null;
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

  /** True when clouds go to a Worker. */
  get inWorker() { return !!this.worker; }

  /**
   * Queues a cloud: `input` is { cloud } (a PointCloud* value) or { packed } (packCloud's form);
   * `options` go to colorCloud (mode, range); `meta` comes back with the result.
   */
  submit(input, options = {}, meta = {}) {
    if (this.disposed) return;
    const seq = ++this.seq;
    this.stats.submitted++;
    const job = { seq, input, options, meta: { ...meta, seq } };
    if (this.busy) {
      if (this.waiting) this.stats.dropped++;
      this.waiting = job;
    } else {
      this.start(job);
    }
  }

  start(job) {
    this.busy = job;
    let packed;
    const t0 = performance.now();
    try {
      packed = job.input.packed || packCloud(job.input.cloud);
    } catch (e) {
      this.finished(job.seq, { ok: false, error: { code: "bad_cloud", message: String(e?.message || e) } });
      return;
    }
    job.packMs = performance.now() - t0;
    job.input = null;  // the objects are not kept once copied
    if (this.worker) {
      const transfer = [packed.positions.buffer, packed.intensity?.buffer, packed.rgb?.buffer].filter(Boolean);
      this.worker.postMessage({ id: job.seq, packed, options: job.options }, [...new Set(transfer)]);
      return;
    }
    Promise.resolve().then(() => {
      const t1 = performance.now();
      const r = { ok: true, ...colorCloud(packed, job.options) };
      r.ms = performance.now() - t1;
      return r;
    }).catch((e) => ({ ok: false, error: { code: "decode_failed", message: String(e?.message || e) } }))
      .then((r) => this.finished(job.seq, r));
  }

  finished(id, result) {
    const job = this.busy;
    if (!job || job.seq !== id) return;
    this.busy = null;
    if (this.disposed) return;
    const r = result && typeof result === "object" ? result : { ok: false, error: { code: "decode_failed", message: "no result" } };
    r.packMs = job.packMs ?? 0;
    if (r.ok) this.stats.decoded++; else this.stats.failed++;
    try {
      this.onResult(r, job.meta);
    } catch (e) {
      console.error("CloudDecoder: onResult failed", e);
    }
    const next = this.waiting;
    this.waiting = null;
    if (next) this.start(next);
  }

  /** The Worker could not run: colour here from now on (the cloud it had is lost). */
  workerFailed() {
    if (!this.worker) return;
    this.worker.terminate();
    this.worker = null;
    const job = this.busy;
    if (job && !this.disposed) {
      this.finished(job.seq, { ok: false, error: { code: "decode_failed", message: "the point cloud Worker stopped; clouds are coloured on the page from now on" } });
    }
  }

  dispose() {
    this.disposed = true;
    this.waiting = null;
    this.worker?.terminate();
    this.worker = null;
  }
}

// A pipe of standard pictures (Image or CompressedImage packets) drawn live in one FrameView: the
// endpoint is connected on start(), reconnected REOPEN_MS after the device or gateway closes it, and
// closed on stop(). What a camera panel shows of preview_stream, frame_stream_compressed or
// frame_stream.

import { errorText } from "../dom.js";
import { FrameView } from "./frame_view.js";
import { imageKind } from "./image_set.js";

const REOPEN_MS = 2000;

export class PictureStream {
  /**
   * @param {HTMLElement} parent
   * @param {object} opts  { pipe (the proxy's pipe member), type (its packet descriptor), view (views/context.js),
   *   label, onError(text|null), onOpen(bool) }
   */
  constructor(parent, opts) {
    this.opts = opts;
    this.kind = imageKind(opts.type);
    this.frames = new FrameView(parent, {
      kind: this.kind, encodings: opts.view?.encodings, clockEnum: opts.view?.clockEnum, label: opts.label,
    });
    this.el = this.frames.el;
    this.ep = null;
    this.running = false;
    this.reopen = 0;
  }

  async start() {
    if (this.running) return;
    this.running = true;
    await this.open();
  }

  async open() {
    clearTimeout(this.reopen);
    if (!this.running || this.ep) return;
    try {
      const ep = await this.opts.pipe.connect(-1);
      if (!this.running) { await ep.close().catch(() => {}); return; }
      this.ep = ep;
      this.opts.onError?.(null);
      this.opts.onOpen?.(true);
      ep.onPacket((v) => this.frames.push(v));
      ep.onClose((err) => {
        if (this.ep !== ep) return;  // closed by us
        this.ep = null;
        this.opts.onOpen?.(false);
        if (!this.running) return;
        this.opts.onError?.(`${this.opts.label}: ${errorText(err ?? new Error("pipe endpoint closed"))}`);
        this.reopen = setTimeout(() => this.open(), REOPEN_MS);
      });
    } catch (e) {
      if (!this.running) return;
      this.opts.onError?.(`${this.opts.label}: ${errorText(e)}`);
      this.reopen = setTimeout(() => this.open(), REOPEN_MS);
    }
  }

  async stop() {
    this.running = false;
    clearTimeout(this.reopen);
    const ep = this.ep;
    this.ep = null;
    if (ep) {
      this.opts.onOpen?.(false);
      await ep.close().catch(() => {});
    }
  }

  dispose() {
    this.stop();
    this.frames.dispose();
  }
}

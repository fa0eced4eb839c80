// A pipe of pictures (packets of a type whose renderer has a picture hook: a camera's Image or
// CompressedImage stream) drawn live in one FrameView: the endpoint is kept open by the device
// session's subscription from start() to stop() (views/live_object.js followPipe; reconnected by the
// subscription when the device or gateway closes it). What a camera panel shows of preview_stream,
// frame_stream_compressed or frame_stream.

import { errorText } from "../dom.js";
import { FrameView } from "./frame_view.js";

export class PictureStream {
  /**
   * @param {HTMLElement} parent
   * @param {object} opts  { live (the object's LiveObject), member (the pipe's name), type (its packet
   *   descriptor: its renderer draws), view (views/context.js), label, onError(text|null), onOpen(bool) }
   */
  constructor(parent, opts) {
    this.opts = opts;
    this.frames = new FrameView(parent, { renderer: opts.type?.renderer, context: opts.view?.text, label: opts.label });
    this.el = this.frames.el;
    this.pipe = null;
  }

  start() {
    if (this.pipe) return;
    const { opts } = this;
    this.pipe = opts.live.followPipe(opts.member, {
      onPacket: (v) => this.frames.push(v),
      onOpen: (open) => opts.onOpen?.(open),
      onError: (e) => opts.onError?.(e ? `${opts.label}: ${errorText(e)}` : null),
    });
  }

  async stop() {
    const pipe = this.pipe;
    this.pipe = null;
    if (pipe) {
      this.opts.onOpen?.(false);
      await pipe.close().catch(() => {});
    }
  }

  dispose() {
    this.stop();
    this.frames.dispose();
  }
}

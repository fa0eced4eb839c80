// The live members of one RR object of a device (its root, or one reached through objrefs) as the views
// subscribe to them: through the device session's subscription (device_session.js; wasm-client
// subscription.mjs), which connects wires and pipe endpoints, connects them again with the package's
// backoff when the device or gateway closes them, and holds event handlers and callbacks. No view
// reconnects anything itself.
//
//   const live = new LiveObject(session.subscription);          // the root object
//   const cam = live.child("Webcams", 0);                       // Webcams[0]
//   const follow = cam.followWire("state", { onValue, onError });
//   const frames = cam.followPipe("FrameStream", { onPacket, onOpen, onError });
//   const off = live.onEvent("Bump", (...args) => ...);

import { followWire } from "./shared_wire.js";

export class LiveObject {
  /**
   * @param {object} subscription  the device session's ServiceSubscription
   * @param {string} [servicePath]  the objref path of this object below the root ("" for the root)
   */
  constructor(subscription, servicePath = "") {
    this.subscription = subscription;
    this.servicePath = servicePath;
  }

  /** The object that objref `name` of this object refers to, at `index` (undefined: a plain objref). */
  child(name, index = undefined) {
    const segment = index === undefined ? name : `${name}[${index}]`;
    return new LiveObject(this.subscription, this.servicePath ? `${this.servicePath}.${segment}` : segment);
  }

  /** Follows wire `name` on the connection all views of it share (views/shared_wire.js followWire). */
  followWire(name, handlers) {
    return followWire(this.subscription, this.servicePath, name, handlers);
  }

  /**
   * Keeps a pipe endpoint of pipe `name` open until close(): onPacket(packet) for each packet,
   * onOpen(open: boolean) as the endpoint opens and closes, onError(error|null) when opening fails or
   * it closes (null once open again). Returns { open (an endpoint is open now), send(packet), close() }.
   */
  followPipe(name, { onPacket, onOpen = () => {}, onError = () => {} }) {
    let pipe;
    try {
      pipe = this.subscription.subscribePipe(name, this.servicePath, 0);
    } catch (e) {
      queueMicrotask(() => onError(e));
      return { open: false, async send() { throw e; }, async close() {} };
    }
    pipe.onPacketReceived((p) => onPacket(p));
    pipe.onConnect(() => { onOpen(true); onError(null); });
    pipe.onDisconnect((c, err) => { onOpen(false); onError(err ?? new Error(`pipe ${name} endpoint closed`)); });
    pipe.onError((err) => onError(err));
    return {
      get open() { return pipe.activePipeEndpointCount > 0; },
      async send(packet) {
        if (!pipe.activePipeEndpointCount) throw new Error("Connect the pipe first");
        await pipe.sendPacketAll(packet);
      },
      close: () => pipe.close(),
    };
  }

  /** `fn(...args)` for every firing of event `name` while the view lives; returns the remover. */
  onEvent(name, fn) {
    return this.subscription.subscribeEvent(name, (...args) => fn(...args.slice(0, -1)), this.servicePath);
  }

  /** Answers callback `name` with `fn(...args)` (null: no answer) until changed; returns a function clearing it. */
  setCallback(name, fn) {
    this.subscription.setCallback(name, fn ? (...args) => fn(...args.slice(0, -1)) : null, this.servicePath);
    return () => {
      try { this.subscription.setCallback(name, null, this.servicePath); } catch { /* the subscription closed */ }
    };
  }
}

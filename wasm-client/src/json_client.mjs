// A client of the gateway's JSON WebSocket API (docs/json-api.md, subprotocol rr-gateway.json.v1) for
// apps that do not load the WebAssembly client: requests as promises, subscriptions as callbacks, and
// the socket opened again with a jittered backoff after any drop, logging in and subscribing again.
// Types: json_client.d.ts; guide: README.md "Subscriptions" → "The JSON client".
import { RRError, toRRError } from "./errors.mjs";
import { backoffDelay, backoffOptions, later, Listeners, ConnectionEvents, GOING_AWAY_WINDOW_MS } from "./backoff.mjs";

export { RRError };

/** Subprotocol of the gateway's JSON WebSocket API (docs/json-api.md "WebSocket"). */
export const JSON_PROTOCOL = "rr-gateway.json.v1";

const ignore = () => {};
const connectionError = (m) => new RRError("RobotRaconteur.ConnectionError", m, 1);
const invalid = (m) => new RRError("RobotRaconteur.InvalidArgument", m, 18);

async function webSocketClass(options) {
  if (options.WebSocket) return options.WebSocket;
  if (typeof globalThis.WebSocket === "function") return globalThis.WebSocket;
  const name = "ws";  // node < 22: the `ws` package (kept out of bundlers' static analysis)
  const m = await import(/* @vite-ignore */ name);
  return m.WebSocket ?? m.default;
}

const TYPED = { double: Float64Array, single: Float32Array, int8: Int8Array, uint8: Uint8Array, int16: Int16Array,
  uint16: Uint16Array, int32: Int32Array, uint32: Uint32Array, int64: BigInt64Array, uint64: BigUint64Array,
  cdouble: Float64Array, csingle: Float32Array };

/** Decodes a binary push (docs/json-api.md "Binary pushes"): numeric arrays become typed arrays over `buffer`. */
export function decodeBinaryPush(buffer) {
  const view = new DataView(buffer);
  if (buffer.byteLength < 8 || view.getUint32(0, false) !== 0x52524a42) throw new RRError("RobotRaconteur.ProtocolError", "not a binary push (no RRJB)", 3);
  const jsonBytes = view.getUint32(4, true);
  if (8 + jsonBytes > buffer.byteLength) throw new RRError("RobotRaconteur.ProtocolError", "binary push shorter than its JSON length", 3);
  const push = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 8, jsonBytes)));
  const base = (8 + jsonBytes + 7) & ~7;
  const resolve = (v) => {
    if (v && typeof v === "object" && "$binary" in v) {
      const T = TYPED[v.type];
      const n = v.length * (v.type === "cdouble" || v.type === "csingle" ? 2 : 1);
      if (!T || base + v.offset + n * T.BYTES_PER_ELEMENT > buffer.byteLength)
        throw new RRError("RobotRaconteur.ProtocolError", "binary push array out of bounds", 3);
      return new T(buffer, base + v.offset, n);
    }
    if (v && typeof v === "object") for (const k of Object.keys(v)) v[k] = resolve(v[k]);
    return v;
  };
  return resolve(push);
}

/** The ws:// URL of the gateway's JSON API from "http(s)://host:port", "ws(s)://host:port" or a page-relative "/". */
function socketUrl(url) {
  const base = typeof location !== "undefined" ? location.href : undefined;
  const u = new URL(url, base);
  u.protocol = u.protocol === "https:" || u.protocol === "wss:" ? "wss:" : "ws:";
  return u.toString();
}

/**
 * Opens a JSON API client of the gateway at `url` (http://, ws:// or, in a page, "/"). Returns at once;
 * requests made before the socket is open wait for it (up to timeoutMs).
 * Options: timeoutMs (per request, and the longest a request waits for the socket; 15000), backoff
 * ({initialMs, maxMs, factor, jitter}: 0.5 s doubling to 10 s, ±25 %), heartbeatPeriodMs (ask the gateway
 * something after this long without receiving, 10000), receiveTimeoutMs (close and reconnect after this
 * long without receiving anything, 15000), username/password or token (logged in on every socket),
 * WebSocket (a WebSocket class; default globalThis.WebSocket, else the `ws` package in node).
 */
export function connectJson(url, options = {}) {
  return new JsonClient(url, options);
}

export class JsonClient extends ConnectionEvents {
  constructor(url, options = {}) {
    super();
    for (const k of ["timeoutMs", "heartbeatPeriodMs", "receiveTimeoutMs"]) {
      const v = options[k];
      if (v !== undefined && !(Number.isInteger(v) && v > 0)) throw invalid(`${k} must be a positive integer (ms), not ${v}`);
    }
    this.url = socketUrl(url);
    this.options = options;
    this.timeoutMs = options.timeoutMs ?? 15000;
    this.heartbeatMs = options.heartbeatPeriodMs ?? 10000;
    this.receiveTimeoutMs = options.receiveTimeoutMs ?? 15000;
    if (this.heartbeatMs >= this.receiveTimeoutMs) throw invalid("heartbeatPeriodMs must be shorter than receiveTimeoutMs");
    this.backoff = backoffOptions(options.backoff);
    /** "connecting" | "connected" | "waiting" (backoff before the next attempt) | "closed" */
    this.state = "connecting";
    this.nextId = 1;
    this.pending = new Map();  // id → {resolve, reject, timer}
    this.waitingForOpen = new Set();
    this.subscriptions = new Set();
    this.bySocketId = new Map();  // the gateway's subscription number → JsonSubscription
    this.deviceStateListeners = new Listeners();
    this.attempt = 0;
    this.connectCount = 0;
    this.open();
  }

  async open() {
    if (this.state === "closed") return;
    this.state = "connecting";
    let WS;
    try {
      WS = await webSocketClass(this.options);
    } catch (e) {
      return this.lost(toRRError(e));
    }
    if (this.state === "closed") return;
    const ws = new WS(this.url, JSON_PROTOCOL);
    ws.binaryType = "arraybuffer";
    this.ws = ws;
    const openGuard = setTimeout(() => this.drop(ws, connectionError(`no WebSocket to ${this.url} within ${this.timeoutMs} ms`)), this.timeoutMs);
    ws.onopen = () => {
      clearTimeout(openGuard);
      if (ws !== this.ws) return;
      this.lastReceive = performance.now();
      this.armLiveness(ws);
      this.ready(ws).catch((e) => this.drop(ws, toRRError(e)));
    };
    ws.onmessage = (ev) => {
      if (ws !== this.ws) return;
      this.lastReceive = performance.now();
      let msg;
      try {
        msg = typeof ev.data === "string" ? JSON.parse(ev.data) : decodeBinaryPush(ev.data);
      } catch (e) {
        return this.errorListeners.emit(toRRError(e));
      }
      this.dispatch(msg);
    };
    ws.onerror = (ev) => this.drop(ws, connectionError(`WebSocket error (${this.url})${ev?.message ? `: ${ev.message}` : ""}`));
    ws.onclose = (ev) => {
      clearTimeout(openGuard);
      // 1001 Going Away: the gateway is stopping (a restart); the next attempts keep the first delay
      if (ev?.code === 1001 && ws === this.ws) this.goingAwayAt = performance.now();
      this.drop(ws, connectionError(`WebSocket closed${ev?.code ? ` (code ${ev.code}${ev.code === 1001 ? ": the server is going away" : ""})` : ""}`));
    };
  }

  /** Logs in when asked to, subscribes again, then lets waiting requests go. */
  async ready(ws) {
    const o = this.options;
    if (o.username !== undefined || o.token !== undefined) {
      const login = o.token !== undefined ? { token: o.token } : { username: o.username, password: o.password ?? "" };
      await this.send(ws, { op: "login", ...login });
    }
    await Promise.all([...this.subscriptions].map((s) => this.resubscribe(s, ws)));
    if (ws !== this.ws) return;
    this.state = "connected";
    this.attempt = 0;
    this.connectCount++;
    for (const w of this.waitingForOpen) w.go();
    this.connectListeners.emit();
  }

  /** Sends a heartbeat request when the gateway has been quiet, drops the socket when it stays quiet. */
  armLiveness(ws) {
    const tick = () => {
      if (ws !== this.ws) return;
      const quiet = performance.now() - this.lastReceive;
      if (quiet > this.receiveTimeoutMs) return this.drop(ws, connectionError(`gateway silent for ${Math.round(quiet)} ms`));
      // Any reply counts: "devices" is the cheapest request every gateway answers (an error before a login is a reply too).
      if (quiet >= this.heartbeatMs) this.send(ws, { op: "devices" }, this.receiveTimeoutMs).catch(() => {});
      this.liveTimer = setTimeout(tick, Math.min(this.heartbeatMs, this.receiveTimeoutMs - this.heartbeatMs) / 2);
    };
    this.liveTimer = setTimeout(tick, this.heartbeatMs / 2);
  }

  drop(ws, error) {
    if (ws !== this.ws || this.state === "closed") return;
    this.ws = null;
    clearTimeout(this.liveTimer);
    ws.onopen = ws.onmessage = ws.onclose = null;
    ws.onerror = ignore;  // node's `ws` emits an error for a socket ended while connecting
    try {
      if (typeof ws.terminate === "function") ws.terminate();
      else ws.close();
    } catch {
      // already closed
    }
    this.lost(error);
  }

  lost(error) {
    for (const [, p] of this.pending) {
      clearTimeout(p.timer);
      p.reject(error);
    }
    this.pending.clear();
    this.bySocketId.clear();
    for (const s of this.subscriptions) s.socketId = null;
    const wasConnected = this.state === "connected";
    this.state = "waiting";
    if (wasConnected) this.disconnectListeners.emit(error);
    else this.errorListeners.emit(error);
    const soon = this.goingAwayAt !== undefined && performance.now() - this.goingAwayAt < GOING_AWAY_WINDOW_MS;
    this.retryTimer = setTimeout(() => this.open(), backoffDelay(soon ? 0 : this.attempt++, this.backoff));
  }

  dispatch(msg) {
    if (msg.id !== undefined && msg.id !== null && this.pending.has(msg.id)) {
      const p = this.pending.get(msg.id);
      this.pending.delete(msg.id);
      clearTimeout(p.timer);
      if (msg.error) p.reject(toRRError({ name: msg.error.name, message: msg.error.message, code: 0 }));
      else p.resolve(msg.result);
      return;
    }
    if (msg.kind === "device_state") return this.deviceStateListeners.emit(msg);
    if (msg.subscription === undefined) return;
    const s = this.bySocketId.get(msg.subscription);
    if (s) s.push(msg);
  }

  /** Sends one request on `ws`; resolves with its result, rejects with its RRError. */
  send(ws, fields, timeoutMs = this.timeoutMs) {
    return new Promise((resolve, reject) => {
      const id = this.nextId++;
      const timer = setTimeout(() => {
        this.pending.delete(id);
        reject(new RRError("RobotRaconteur.RequestTimeout", `no answer to "${fields.op}" within ${timeoutMs} ms`, 12));
      }, timeoutMs);
      this.pending.set(id, { resolve, reject, timer });
      try {
        ws.send(JSON.stringify({ id, ...fields }));
      } catch (e) {
        clearTimeout(timer);
        this.pending.delete(id);
        reject(connectionError(String(e?.message ?? e)));
      }
    });
  }

  /** Waits for the socket (up to timeoutMs), then sends. Requests are not sent again after a drop. */
  request(fields) {
    if (this.state === "closed") return Promise.reject(connectionError("client closed"));
    if (this.state === "connected") return this.send(this.ws, fields);
    return new Promise((resolve, reject) => {
      const w = {
        go: () => {
          clearTimeout(w.timer);
          this.waitingForOpen.delete(w);
          this.send(this.ws, fields).then(resolve, reject);
        },
        fail: (e) => {
          clearTimeout(w.timer);
          this.waitingForOpen.delete(w);
          reject(e);
        },
      };
      w.timer = setTimeout(() => w.fail(connectionError(`not connected to ${this.url} within ${this.timeoutMs} ms`)), this.timeoutMs);
      this.waitingForOpen.add(w);
    });
  }

  // --- operations (docs/json-api.md "Client → gateway") ---------------------------------------------

  /** The device list (op "devices"). */
  devices() {
    return this.request({ op: "devices" });
  }

  /** A handle on device `name` whose methods fill in `device` (and `object` when given). */
  device(name, object) {
    return new JsonDevice(this, name, object);
  }

  /** Subscribes to wire, event or pipe `member` (see JsonDevice.subscribe). */
  subscribe(device, member, handler, options = {}) {
    if (typeof handler !== "function") return Promise.reject(invalid("subscribe needs a handler function"));
    const spec = { device, member, object: options.object, binary: !!options.binary };
    // Checked by the gateway (a bad value rejects with its InvalidArgument); kept for every resubscription.
    if (options.maxRateHz !== undefined) spec.maxRateHz = options.maxRateHz;
    if (options.queueLength !== undefined) spec.queueLength = options.queueLength;
    const s = new JsonSubscription(this, spec, handler);
    // Kept (and subscribed again on later sockets) only once the gateway accepted it the first time.
    return this.request({ op: "subscribe", ...s.fields() }).then((r) => {
      s.kind = r.kind;
      if (this.state === "closed") {
        s.closed = true;
        return s;
      }
      this.subscriptions.add(s);
      s.socketId = r.subscription;
      this.bySocketId.set(r.subscription, s);
      return s;
    });
  }

  async resubscribe(s, ws) {
    if (s.closed) return;
    try {
      const r = await this.send(ws, { op: "subscribe", ...s.fields() });
      if (ws !== this.ws || s.closed) return;
      s.kind = r.kind;
      s.socketId = r.subscription;
      this.bySocketId.set(r.subscription, s);
      s.resubscribed++;
    } catch (e) {
      if (ws !== this.ws) return;
      this.errorListeners.emit(toRRError(e));
      s.scheduleRetry();
    }
  }

  // onConnect(fn()) after every (re)connection (logged in and subscribed again); onDisconnect(fn(error))
  // after every lost connection; onError(fn(error)): a failed connection attempt, login or
  // resubscription (ConnectionEvents).
  /** `fn(push)` for every device_state push ({device, state, reason, ...}). Returns the remover. */
  onDeviceState(fn) {
    return this.deviceStateListeners.add(fn);
  }

  /** Closes the socket and stops reconnecting. */
  close() {
    if (this.state === "closed") return;
    const ws = this.ws;
    this.state = "closed";
    this.ws = null;
    clearTimeout(this.retryTimer);
    clearTimeout(this.liveTimer);
    for (const w of [...this.waitingForOpen]) w.fail(connectionError("client closed"));
    for (const [, p] of this.pending) {
      clearTimeout(p.timer);
      p.reject(connectionError("client closed"));
    }
    this.pending.clear();
    for (const s of this.subscriptions) s.closed = true;
    this.subscriptions.clear();
    if (ws) {
      ws.onopen = ws.onmessage = ws.onclose = null;
      ws.onerror = ignore;
      try {
        ws.close();
      } catch {
        // already closed
      }
    }
  }
}

/** Member operations on one device (and optionally one object below its root). */
class JsonDevice {
  constructor(client, name, object) {
    this.client = client;
    this.name = name;
    this.object = object;
  }
  base(member, extra = {}) {
    const f = { device: this.name, member, ...extra };
    if (this.object !== undefined) f.object = this.object;
    return f;
  }
  /** The device's description (op "device": state, definitions, members). */
  info() {
    return this.client.request({ op: "device", device: this.name });
  }
  /** The object at `path` below this one ("Webcams[0]"). */
  child(path) {
    return new JsonDevice(this.client, this.name, this.object ? `${this.object}.${path}` : path);
  }
  /** Reads property `member`. */
  get(member) {
    return this.client.request({ op: "get", ...this.base(member) }).then((r) => r.value);
  }
  /** Writes property `member`. */
  set(member, value) {
    return this.client.request({ op: "set", ...this.base(member, { value }) }).then(() => undefined);
  }
  /** Calls function `member` (args: array or object by name); resolves with its return value (generators: the items). */
  call(member, args = [], options = {}) {
    const extra = { args };
    if (options.maxItems !== undefined) extra.max_items = options.maxItems;
    return this.client.request({ op: "call", ...this.base(member, extra) }).then((r) => ("items" in r ? r.items : r.return));
  }
  /** The wire's newest value: {value, time}. */
  peek(member) {
    return this.client.request({ op: "peek", ...this.base(member) });
  }
  /**
   * Subscribes to wire, event or pipe `member`; resolves with a JsonSubscription once the gateway
   * accepted it. `handler(value, push)`: a wire's value, an event's args object, a pipe's packet; push is
   * the whole message (time, dropped). Kept across reconnects; a pipe the device closed is subscribed again.
   */
  subscribe(member, handler, options = {}) {
    return this.client.subscribe(this.name, member, handler, { object: this.object, ...options });
  }
}

/** One subscription, subscribed again on every new socket (and after the device closed a pipe). */
class JsonSubscription {
  constructor(client, spec, handler) {
    this.client = client;
    this.spec = spec;
    this.handler = handler;
    this.kind = null;
    this.socketId = null;
    this.closed = false;
    this.resubscribed = 0;
    this.attempt = 0;
    this.closeListeners = new Listeners();
  }
  fields() {
    const f = { device: this.spec.device, member: this.spec.member };
    if (this.spec.object !== undefined) f.object = this.spec.object;
    if (this.spec.binary) f.binary = true;
    if (this.spec.maxRateHz !== undefined) f.max_rate_hz = this.spec.maxRateHz;
    if (this.spec.queueLength !== undefined) f.queue_length = this.spec.queueLength;
    return f;
  }
  push(msg) {
    if (this.closed) return;
    if (msg.kind === "closed") {
      // The device closed it (a pipe when the device is lost): subscribe again on this socket.
      this.client.bySocketId.delete(this.socketId);
      this.socketId = null;
      this.closeListeners.emit(toRRError({ ...msg.error, code: 0 }));
      return this.scheduleRetry();
    }
    if (msg.error) return this.client.errorListeners.emit(toRRError({ ...msg.error, code: 0 }));
    this.attempt = 0;
    if (msg.kind === "event") later(this.handler, msg.args, msg);
    else if (msg.kind === "wire" || msg.kind === "pipe") later(this.handler, msg.value, msg);
  }
  scheduleRetry() {
    const c = this.client;
    const ws = c.ws;
    setTimeout(() => {
      if (!this.closed && ws && ws === c.ws && this.socketId === null) c.resubscribe(this, ws);
    }, backoffDelay(this.attempt++, c.backoff));
  }
  /** `fn(error)` whenever the gateway ended it (it is subscribed again). Returns the remover. */
  onClose(fn) {
    return this.closeListeners.add(fn);
  }
  /** Sets the OutValue of a subscribed wire. */
  setOutValue(value) {
    return this.whenLive().then((id) => this.client.request({ op: "set_out_value", subscription: id, value })).then(() => undefined);
  }
  /** Sends a packet on a subscribed pipe; resolves with its packet number. */
  send(value, requestAck = false) {
    return this.whenLive().then((id) => this.client.request({ op: "send", subscription: id, value, requestack: requestAck }))
      .then((r) => r.packetnumber);
  }
  whenLive() {
    if (this.socketId === null) return Promise.reject(connectionError("subscription not active (reconnecting)"));
    return Promise.resolve(this.socketId);
  }
  /** Ends the subscription. */
  async close() {
    if (this.closed) return;
    this.closed = true;
    this.client.subscriptions.delete(this);
    const id = this.socketId;
    this.socketId = null;
    if (id !== null) {
      this.client.bySocketId.delete(id);
      if (this.client.state === "connected") await this.client.request({ op: "unsubscribe", subscription: id }).catch(() => {});
    }
  }
}

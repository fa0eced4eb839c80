// Robot Raconteur client for browsers and node (>= 18): the C++ sans-IO client core compiled to
// WebAssembly (robotraconteur_wasm.mjs), a WebSocket transport, and object proxies built from the
// service's robdef. API and value mapping: README.md; types: index.d.ts.
import { RRError, toRRError } from "./errors.mjs";
import { makeProxy } from "./proxy.mjs";
import { ServiceSubscription, WireSubscription, PipeSubscription, matchesFilter } from "./subscription.mjs";
import { DEFAULT_BACKOFF, backoffDelay } from "./backoff.mjs";
import { loadModule } from "./wasm_module.mjs";
import { parseObjectPath } from "./object_path.mjs";

export { RRError, toRRError, ServiceSubscription, WireSubscription, PipeSubscription, matchesFilter, DEFAULT_BACKOFF, backoffDelay,
  loadModule, parseObjectPath };

/** Subprotocol of RR over WebSocket (wire.md §8). */
export const WEBSOCKET_PROTOCOL = "robotraconteur.robotraconteur.com";

const inNode = typeof process !== "undefined" && !!process.versions?.node;

async function webSocketClass(options) {
  if (options.WebSocket) return options.WebSocket;
  // A given CA needs the `ws` package's TLS options: node's global WebSocket (node 22) takes none.
  if (typeof globalThis.WebSocket === "function" && (options.ca === undefined || !inNode)) return globalThis.WebSocket;
  const name = "ws";  // node: the `ws` package (kept out of bundlers' static analysis)
  let m;
  try {
    m = await import(/* @vite-ignore */ name);
  } catch (e) {
    throw new RRError("RobotRaconteur.InvalidOperation",
      `no WebSocket implementation: this runtime has no globalThis.WebSocket${options.ca !== undefined ? " usable with the ca option" : ""}` +
      ` and the "ws" package could not be loaded (${e?.code ?? e?.message ?? e}); install it next to robotraconteur-wasm` +
      " (npm install ws) or pass connect(url, { WebSocket })", 17);
  }
  const WS = m.WebSocket ?? m.default;
  if (typeof WS !== "function")
    throw new RRError("RobotRaconteur.InvalidOperation", 'the "ws" package gave no WebSocket class (install ws >= 8)', 17);
  return WS;
}

/**
 * Splits an RR URL (`rr+ws://host:port/?service=name&nodeid=…&nodename=…`, also rr+wss) into the
 * WebSocket URL and the query. rrs+ (TLS inside RR) is not supported: use rr+wss.
 */
export function parseUrl(url) {
  const m = /^([a-z+]+):\/\/(.*)$/i.exec(url);
  if (!m) throw new RRError("RobotRaconteur.InvalidArgument", `not an RR URL: ${url}`, 18);
  const scheme = m[1].toLowerCase();
  const wsScheme = { "rr+ws": "ws", "rr+wss": "wss", ws: "ws", wss: "wss" }[scheme];
  if (!wsScheme)
    throw new RRError("RobotRaconteur.InvalidArgument", `unsupported scheme "${scheme}" (use rr+ws or rr+wss)`, 18);
  const u = new URL(`${wsScheme}://${m[2]}`);
  const service = u.searchParams.get("service") ?? "";
  if (!service) throw new RRError("RobotRaconteur.InvalidArgument", `URL names no service: ${url}`, 18);
  return {
    wsUrl: u.toString(),
    service,
    nodeId: u.searchParams.get("nodeid") ?? "",
    nodeName: u.searchParams.get("nodename") ?? "",
  };
}

const now = () => performance.now();
const ignore = () => {};

let webcrypto = globalThis.crypto;
function randomBytes(n) {
  const b = new Uint8Array(n);
  webcrypto.getRandomValues(b);
  return b;
}

/** One transport connection with one client session (the NativeClient) on it. */
export class Connection {
  constructor(M, url, options, WebSocketImpl) {
    this.url = url;
    this.options = options;
    this.state = "connecting";
    this.closeListeners = new Set();
    this.proxies = new Map();
    this.flushQueued = false;
    this.timer = null;
    this.timerAt = -1;
    const endpoint = new Uint32Array(randomBytes(4).buffer)[0] || 1;
    this.native = new M.NativeClient({
      service: url.service,
      targetNodeId: url.nodeId,
      targetNodeName: url.nodeName,
      nodeName: options.nodeName ?? "",
      username: options.username ?? "",
      password: options.password ?? "",
      requestTimeoutMs: options.timeoutMs ?? 15000,
      heartbeatPeriodMs: options.heartbeatPeriodMs ?? 10000,
      receiveTimeoutMs: options.receiveTimeoutMs ?? 15000,
      nodeId: randomBytes(16),
      endpoint,
      now: now(),
    });
    // ca: the `ws` package's TLS option (node); a browser checks certificates against its own store.
    this.ws = options.ca === undefined ? new WebSocketImpl(url.wsUrl, WEBSOCKET_PROTOCOL)
      : new WebSocketImpl(url.wsUrl, WEBSOCKET_PROTOCOL, { ca: options.ca });
    this.ws.binaryType = "arraybuffer";
  }

  /** Resolves with the root object's proxy once the client session is established. */
  open() {
    return new Promise((resolve, reject) => {
      const timeoutMs = this.options.timeoutMs ?? 15000;
      const guard = setTimeout(() => this.fail(`connect timed out after ${timeoutMs} ms`), timeoutMs);
      this.native.setHandlers(
        (err, root) => {
          clearTimeout(guard);
          if (err) {
            reject(toRRError(err));
            return;
          }
          this.state = "connected";
          const info = this.native.info();
          this.nodeName = info.nodeName;
          this.nodeId = info.nodeId;
          this.definitions = info.definitions;
          queueMicrotask(() => {
            try {
              resolve(this.proxy(root.path));
            } catch (e) {
              reject(toRRError(e));
            }
          });
        },
        (err) => this.onClosed(toRRError(err)),
        (path) => this.forget(path),
      );
      this.ws.onopen = () => this.flush();
      this.ws.onmessage = (ev) => {
        if (this.state === "closed") return;
        if (typeof ev.data === "string") return this.fail("text frame on an RR WebSocket");
        const r = this.native.feed(new Uint8Array(ev.data), now());
        this.scheduleFlush();
        if (!r.ok) this.flush();
      };
      // node's `ws` says why (e.g. "self-signed certificate"); browsers give no reason.
      this.ws.onerror = (ev) => this.fail(`WebSocket error (${this.url.wsUrl})${ev?.message ? `: ${ev.message}` : ""}`);
      this.ws.onclose = (ev) => {
        // 1001 Going Away: the server is stopping (a restart); subscriptions come back sooner then.
        if (ev?.code) this.closeCode = ev.code;
        this.fail(`WebSocket closed${ev?.code ? ` (code ${ev.code}${ev.code === 1001 ? ": the server is going away" : ""})` : ""}`);
      };
    });
  }

  /** The transport went away: the native client fails what is pending and reports the close. */
  fail(message) {
    if (this.state === "closed" || this.deleted) return;
    this.native.transportClosed(message);
    this.flush();
    this.onClosed(new RRError("RobotRaconteur.ConnectionError", message, 1));
  }

  onClosed(error) {
    if (this.state === "closed") return;
    this.state = "closed";
    // Format the stack now: an unformatted V8 stack trace holds the `this` of its frames (this closed
    // connection and all its proxies) for as long as anyone keeps the error (a reconnect loop does).
    void error?.stack;
    this.closeError = error;
    if (this.timer) clearTimeout(this.timer);
    try {
      // node's `ws` would wait up to 30 s for the close handshake of a peer that may be gone: drop the
      // socket at once unless this side closed cleanly.
      if (error && typeof this.ws.terminate === "function") this.ws.terminate();
      else this.ws.close();
    } catch {
      // already closed
    }
    // A browser keeps a closing WebSocket (and so its handlers, this connection, its proxies) until the
    // close handshake ends or times out: let go of them now. onerror stays a no-op: node's `ws` emits
    // an error for a socket ended while connecting, which would be an uncaught exception without one.
    this.ws.onopen = this.ws.onmessage = this.ws.onclose = null;
    this.ws.onerror = ignore;
    for (const fn of this.closeListeners) queueMicrotask(() => fn(error));
    // Free the native object once no C++ frame is on the stack.
    setTimeout(() => {
      if (!this.deleted) {
        this.deleted = true;
        this.native.delete();
      }
    }, 0);
  }

  forget(path) {
    for (const p of this.proxies.keys()) if (p === path || p.startsWith(path + ".")) this.proxies.delete(p);
  }

  scheduleFlush() {
    if (this.flushQueued) return;
    this.flushQueued = true;
    queueMicrotask(() => {
      this.flushQueued = false;
      this.flush();
    });
  }

  /** Sends pending output and re-arms the timer at the native client's next deadline. */
  flush() {
    if (this.deleted) return;
    if (this.ws.readyState === 1) {
      for (let out = this.native.takeOutput(); out; out = this.native.takeOutput()) this.ws.send(out);
    }
    if (this.native.isClosed() && this.state !== "closed") {
      this.onClosed(this.closeError ?? new RRError("RobotRaconteur.ConnectionError", "connection closed", 1));
      return;
    }
    const d = this.native.nextDeadline();
    if (d >= 0 && d !== this.timerAt) {
      if (this.timer) clearTimeout(this.timer);
      this.timerAt = d;
      this.timer = setTimeout(() => {
        this.timer = null;
        this.timerAt = -1;
        if (this.deleted) return;
        this.native.onTimer(now());
        this.flush();
      }, Math.max(0, d - now()));
    }
  }

  /** Runs `start(cb)` on the native client; resolves/rejects with what cb receives. */
  op(start) {
    return new Promise((resolve, reject) => {
      if (this.deleted || this.state === "closed")
        return reject(new RRError("RobotRaconteur.ConnectionError", "connection closed", 1));
      start((err, value) => (err ? reject(toRRError(err)) : resolve(value)));
      this.scheduleFlush();
    });
  }

  /** Runs a synchronous native call returning {ok, value | error}; throws RRError on error. */
  sync(fn) {
    if (this.deleted || this.state === "closed")
      throw new RRError("RobotRaconteur.ConnectionError", "connection closed", 1);
    const r = fn(this.native);
    this.scheduleFlush();
    if (!r.ok) throw toRRError(r.error);
    return r.value;
  }

  proxy(path) {
    let p = this.proxies.get(path);
    if (!p) {
      const desc = this.sync((n) => n.describe(path));
      // An objref may have pulled definitions of another service.
      if (this.proxies.size) this.definitions = this.native.info().definitions;
      p = makeProxy(this, desc);
      this.proxies.set(path, p);
    }
    return p;
  }

  close() {
    if (this.state === "closed") return Promise.resolve();
    return new Promise((resolve) => {
      this.closeListeners.add(() => resolve());
      this.native.disconnect(now());
      this.flush();
    });
  }

  /** The `$client` object of every proxy. */
  get clientApi() {
    if (!this._clientApi) {
      const c = this;
      this._clientApi = {
        close: () => c.close(),
        get state() {
          return c.state;
        },
        onClose(fn) {
          c.closeListeners.add(fn);
          return () => c.closeListeners.delete(fn);
        },
        get nodeName() {
          return c.nodeName;
        },
        get nodeId() {
          return c.nodeId;
        },
        get url() {
          return c.url.wsUrl;
        },
        get closeCode() {
          return c.closeCode ?? null;
        },
      };
    }
    return this._clientApi;
  }
}

/**
 * Connects to the service named in `url` (rr+ws:// or rr+wss://) and returns the root object's proxy.
 * Options: timeoutMs (connect and per request, default 15000), heartbeatPeriodMs (send an RR
 * ConnectionTest after this long without sending, default 10000) and receiveTimeoutMs (close the
 * connection with ConnectionError after this long without receiving anything, default 15000: a dead
 * peer or a network that silently drops packets is noticed within it; wire.md §6.3), username, password, nodeName,
 * WebSocket (a WebSocket class; default globalThis.WebSocket, else the `ws` package in node), ca (node
 * only: the PEM certificates an rr+wss server's chain must lead to, instead of node's own list).
 */
export async function connect(url, options = {}) {
  try {
    return await connectOnce(url, options);
  } catch (e) {
    // Every failure reaches the caller as an RRError, also one from node or the runtime (a missing
    // .wasm file, a refused import).
    throw e instanceof RRError ? e : new RRError("RobotRaconteur.ConnectionError", String(e?.message ?? e), 1);
  }
}

async function connectOnce(url, options) {
  const u = parseUrl(url);
  for (const k of ["timeoutMs", "heartbeatPeriodMs", "receiveTimeoutMs"]) {
    const v = options[k];
    if (v !== undefined && !(Number.isInteger(v) && v > 0 && v <= 2 ** 31 - 1))
      throw new RRError("RobotRaconteur.InvalidArgument", `${k} must be a positive integer (ms), not ${v}`, 18);
  }
  if ((options.heartbeatPeriodMs ?? 10000) >= (options.receiveTimeoutMs ?? 15000))
    throw new RRError("RobotRaconteur.InvalidArgument",
      "heartbeatPeriodMs must be shorter than receiveTimeoutMs (the peer answers each heartbeat)", 18);
  if (options.ca !== undefined && !inNode && !options.WebSocket)
    throw new RRError("RobotRaconteur.InvalidArgument",
      "the ca option works in node only: a browser checks an rr+wss certificate against its own trust store", 18);
  if (options.ca !== undefined && !u.wsUrl.startsWith("wss:"))
    throw new RRError("RobotRaconteur.InvalidArgument", `the ca option is for rr+wss URLs, not ${url}`, 18);
  if (!webcrypto) webcrypto = (await import("node:crypto")).webcrypto;  // node 18 has no global crypto
  const M = await loadModule();
  const WS = await webSocketClass(options);
  const c = new Connection(M, u, options, WS);
  try {
    return await c.open();
  } catch (e) {
    c.fail(String(e.message));
    throw e;
  }
}

/**
 * A ServiceSubscription (README.md "Subscriptions"; the official ServiceSubscription's semantics): keeps
 * a connection to each service `target` names, connects again after any drop (backoff: 0.5 s doubling
 * to 10 s, ±25 % jitter; `options.backoff` {initialMs, maxMs, factor, jitter}) and restores the wires,
 * pipes, events and callbacks opened through it. Returns at once; connecting goes on in the background.
 *
 * `target`: an RR URL, an array of URLs, or a filter resolved through the gateway's discovery:
 * {gateway: "http://host:port", serviceTypes?, serviceNames?, nodes?: [{nodeName?, nodeId?}],
 *  attributes?: {name: text | RegExp}, attributesMatch?: "all" | "any", predicate?: (info) => bool,
 *  maxConnections?}, matched against the gateway's devices (GET /api/devices) and discovered services
 * (GET /api/discovered) every `options.discoveryIntervalMs` (5000).
 * `options`: connect()'s options (used for every connection: timeoutMs, heartbeatPeriodMs,
 * receiveTimeoutMs, username, password, ...), plus backoff and discoveryIntervalMs.
 * Throws RRError InvalidArgument for a malformed target or option.
 */
export function subscribe(target, options = {}) {
  return new ServiceSubscription(target, options, connect);
}

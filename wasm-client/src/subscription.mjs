// Reconnecting subscriptions after the official library's ServiceSubscription, WireSubscription and
// PipeSubscription (README.md "Subscriptions"): keep a client connection to each matching service,
// connect again with a jittered backoff after any drop, and restore on the new connection the wires,
// pipe endpoints, event handlers and callbacks the app asked for.
import { RRError, toRRError } from "./errors.mjs";
import { backoffDelay, backoffOptions, later, Listeners, ConnectionEvents, GOING_AWAY_WINDOW_MS } from "./backoff.mjs";
import { parseObjectPath } from "./object_path.mjs";

const now = () => performance.now();
const connectionError = (m) => new RRError("RobotRaconteur.ConnectionError", m, 1);
/** A copy to keep: a V8 error's unformatted stack trace holds the `this` of its frames (the closed
 * connection and, through it, its proxies) for as long as the error lives. */
const keepable = (e) => (e ? new RRError(e.errorName, e.message, e.code) : null);
const invalid = (m) => new RRError("RobotRaconteur.InvalidArgument", m, 18);

const INT32 = /^-?[0-9]+$/;

/**
 * Walks `path` (an objref path relative to the root: "child", "child_by_int[7]", "a.b[x]"; "" = root;
 * parsed by the core's parser, object_path.mjs) from `root`, one objref request per segment. Resolves
 * with the object's proxy. Rejects with RRError InvalidArgument for a path that does not parse or an
 * int32 objref's index that is not an int32, MemberNotFound for a segment that is not an objref.
 */
export async function resolveObject(root, path) {
  let obj = root;
  if (!path) return obj;
  for (const seg of await parseObjectPath(path)) {
    const member = obj.$members.find((x) => x.name === seg.name);
    if (!member || member.kind !== "objref") throw new RRError("RobotRaconteur.MemberNotFound", `no objref "${seg.name}" on ${obj.$type}`, 9);
    let index = seg.index;
    if (index !== undefined && member.index === "int32") {
      if (!INT32.test(index) || Number(index) !== (Number(index) | 0))
        throw invalid(`object path "${path}": objref "${seg.name}" takes an int32 index, not "${index}"`);
      index = Number(index);
    }
    obj = await obj[seg.name].get(index);
  }
  return obj;
}

const NODE_ID_CLEAN = /[{}\-\s]/g;
const sameNodeId = (a, b) => !!a && !!b && a.replace(NODE_ID_CLEAN, "").toLowerCase() === b.replace(NODE_ID_CLEAN, "").toLowerCase();
/** A discovery attribute value as text (the JSON API gives varvalues as {type, value} or plain JSON). */
const attributeText = (v) => (v && typeof v === "object" && "value" in v ? String(v.value) : String(v));

/**
 * Whether the service `info` ({name, serviceName, nodeName, nodeId, rootObjectType, implements,
 * attributes}) passes `filter`; the fields of the official ServiceSubscriptionFilter plus the types.
 */
export function matchesFilter(info, filter) {
  const types = filter.serviceTypes ?? [];
  if (types.length && !types.some((t) => t === info.rootObjectType || (info.implements ?? []).includes(t))) return false;
  const names = filter.serviceNames ?? [];
  if (names.length && !names.some((n) => n === info.name || n === info.serviceName)) return false;
  const nodes = filter.nodes ?? [];
  if (nodes.length && !nodes.some((n) => (!n.nodeName || n.nodeName === info.nodeName) && (!n.nodeId || sameNodeId(n.nodeId, info.nodeId))))
    return false;
  const attrs = Object.entries(filter.attributes ?? {});
  if (attrs.length) {
    const test = ([k, want]) => {
      const have = info.attributes?.[k];
      if (have === undefined) return false;
      const text = attributeText(have);
      return want instanceof RegExp ? want.test(text) : String(want) === text;
    };
    if ((filter.attributesMatch ?? "all") === "any" ? !attrs.some(test) : !attrs.every(test)) return false;
  }
  return filter.predicate ? !!filter.predicate(info) : true;
}

/** rr+tcp://host:port/?… → rr+ws://host:port/?… (a browser cannot open TCP; RR servers take ws on the same port). */
function wsUrlOf(url) {
  const m = /^rr\+tcp:\/\/(.*)$/i.exec(url);
  if (!m || /\[fe80|%/i.test(m[1])) return null;  // link-local addresses are useless to a browser
  return `rr+ws://${m[1]}`;
}

/** The gateway's HTTP origin and its rr+ws origin from "http(s)://host:port" or "rr+ws(s)://host:port". */
function gatewayOrigins(g) {
  const u = new URL(g.replace(/^rr\+ws/i, "http").replace(/^ws/i, "http"));
  return { http: u.origin, rr: u.origin.replace(/^http/, "rr+ws") };
}

/**
 * One matched service: its connection state, its proxy while connected. Read-only to the app
 * (`sub.clients`).
 */
class SubscriptionClient {
  constructor(id, url, info, fixed) {
    this.id = id;
    this.url = url;
    this.serviceInfo = info;
    this.fixed = fixed;  // given by URL: never dropped for not being listed
    this.listed = true;
    this.removed = false;
    /** "connecting" | "connected" | "waiting" (backoff before the next attempt) | "closed" */
    this.state = "connecting";
    this.proxy = null;
    this.lastError = null;
    this.connectCount = 0;
    this.attempt = 0;
    this.generation = 0;
    this.wake = null;
  }
}

/**
 * ServiceSubscription: see subscribe() in robotraconteur.mjs for the target and options.
 * `connectFn(url, options)` is robotraconteur.mjs connect (injected: no import cycle).
 */
export class ServiceSubscription extends ConnectionEvents {
  constructor(target, options, connectFn) {
    super();
    this.options = options;
    this.connectFn = connectFn;
    this.backoff = backoffOptions(options.backoff);
    this.connectOptions = { ...options };
    delete this.connectOptions.backoff;
    this.closed = false;
    this.clientsById = new Map();
    this.wires = new Set();
    this.pipes = new Set();
    this.events = new Set();
    this.callbacks = new Map();
    this.connectingListeners = new Listeners();
    this.defaultWaiters = [];
    if (typeof target === "string" || Array.isArray(target)) {
      const urls = typeof target === "string" ? [target] : target;
      if (!urls.length || urls.some((u) => typeof u !== "string")) throw invalid("subscribe: target must be a URL, URLs or a filter object");
      for (const u of urls) this.addClient(new SubscriptionClient(u, u, null, true));
    } else if (target && typeof target === "object") {
      if (typeof target.gateway !== "string") throw invalid("subscribe: a filter needs `gateway` (the gateway's http:// or rr+ws:// origin)");
      if (target.attributesMatch !== undefined && !["all", "any"].includes(target.attributesMatch))
        throw invalid(`subscribe: attributesMatch is "all" or "any", not ${target.attributesMatch}`);
      this.filter = target;
      this.origins = gatewayOrigins(target.gateway);
      this.maxConnections = target.maxConnections ?? Infinity;
      this.discoveryIntervalMs = options.discoveryIntervalMs ?? 5000;
      this.discover();
    } else {
      throw invalid("subscribe: target must be a URL, URLs or a filter object");
    }
  }

  // --- discovery ------------------------------------------------------------------------------------

  /** Reads the gateway's devices and discovered services, starts clients for new matches, then again later. */
  async discover() {
    if (this.closed) return;
    try {
      const found = await this.candidates();
      if (this.closed) return;
      for (const c of this.clientsById.values()) if (!c.fixed) c.listed = found.has(c.id);
      for (const [id, { url, info }] of found) {
        if (this.clientsById.size >= this.maxConnections) break;
        if (!this.clientsById.has(id)) this.addClient(new SubscriptionClient(id, url, info, false));
      }
    } catch (e) {
      this.errorListeners.emit(toRRError(e), null);
    }
    if (!this.closed) this.discoveryTimer = setTimeout(() => this.discover(), this.discoveryIntervalMs);
  }

  async candidates() {
    const get = async (path) => {
      const r = await fetch(`${this.origins.http}${path}`, { credentials: "include" });
      if (r.status === 404 && path === "/api/discovered") return { nodes: [] };  // discovery off
      if (!r.ok) throw connectionError(`GET ${path}: HTTP ${r.status}`);
      return r.json();
    };
    const [devices, discovered] = await Promise.all([get("/api/devices"), get("/api/discovered")]);
    const found = new Map();
    // The gateway's own devices: reachable as rr+ws on the gateway whatever the device's transport.
    for (const d of devices) {
      const info = { name: d.name, serviceName: d.name, nodeName: "", nodeId: "", rootObjectType: d.object_type ?? "",
        implements: [], attributes: {}, device: d.name };
      found.set(`device:${d.name}`, { url: `${this.origins.rr}/?service=${encodeURIComponent(d.name)}`, info });
    }
    for (const node of discovered.nodes ?? []) {
      for (const s of node.services ?? []) {
        const info = { name: s.device ?? s.name, serviceName: s.name, nodeName: s.nodename ?? node.nodename,
          nodeId: s.nodeid ?? node.nodeid, rootObjectType: s.root_object_type ?? "", implements: s.implements ?? [],
          attributes: s.attributes ?? {}, device: s.device ?? null, urls: s.urls ?? [] };
        if (s.device) {
          found.set(`device:${s.device}`, { url: `${this.origins.rr}/?service=${encodeURIComponent(s.device)}`, info });
          continue;
        }
        const url = (s.urls ?? []).map(wsUrlOf).find(Boolean);
        if (url) found.set(`node:${info.nodeId}/${s.name}`, { url, info });
      }
    }
    for (const [id, c] of found) if (!matchesFilter(c.info, this.filter)) found.delete(id);
    return found;
  }

  // --- one client's connection loop -----------------------------------------------------------------

  addClient(c) {
    this.clientsById.set(c.id, c);
    // started after the caller's current task, so listeners added right after subscribe() hear the first attempt
    queueMicrotask(() => this.run(c).catch((e) => this.errorListeners.emit(toRRError(e), c)));
  }

  /** Waits `ms`, or less when close() or a removal wakes the client (at once when that came first). */
  sleep(c, ms) {
    if (this.closed || c.removed) return Promise.resolve();
    return new Promise((resolve) => {
      const t = setTimeout(() => {
        c.wake = null;
        resolve();
      }, ms);
      c.wake = () => {
        clearTimeout(t);
        c.wake = null;
        resolve();
      };
    });
  }

  async run(c) {
    while (!this.closed && !c.removed) {
      c.state = "connecting";
      this.connectingListeners.emit(c);
      let proxy;
      try {
        proxy = await this.connectFn(c.url, this.connectOptions);
      } catch (e) {
        if (this.closed || c.removed) break;
        c.lastError = keepable(toRRError(e));
        c.state = "waiting";
        this.errorListeners.emit(toRRError(e), c);
        if (!c.fixed && !c.listed) break;
        const soon = c.goingAwayAt !== undefined && now() - c.goingAwayAt < GOING_AWAY_WINDOW_MS;
        await this.sleep(c, backoffDelay(soon ? 0 : c.attempt++, this.backoff));
        continue;
      }
      if (this.closed || c.removed) {
        await proxy.$client.close();
        break;
      }
      const lost = new Promise((resolve) => proxy.$client.onClose(resolve));
      c.proxy = proxy;
      c.state = "connected";
      c.attempt = 0;
      c.connectCount++;
      const gen = ++c.generation;
      this.restore(c, proxy, gen);
      this.connectListeners.emit(c, proxy);
      for (const w of this.defaultWaiters.splice(0)) w(proxy);
      const error = await lost;
      // 1001: the server said it is going away (a restart): come back at the first delay for a while
      c.goingAwayAt = proxy.$client.closeCode === 1001 ? now() : undefined;
      c.proxy = null;
      c.generation++;
      for (const s of [...this.wires, ...this.pipes]) s.detach(c, error ?? null);
      if (this.closed || c.removed) break;
      c.state = "waiting";
      c.lastError = keepable(error);
      this.disconnectListeners.emit(c, error ?? null);
      if (!c.fixed && !c.listed) break;
      await this.sleep(c, backoffDelay(c.attempt++, this.backoff));
    }
    c.state = "closed";
    c.proxy = null;
    if (!this.closed) this.clientsById.delete(c.id);
  }

  /** Puts back on a new connection what the app opened on the subscription. */
  restore(c, proxy, gen) {
    for (const e of this.events) this.attachEvent(e, c, proxy, gen);
    for (const cb of this.callbacks.values()) this.attachCallback(cb, c, proxy, gen);
    for (const s of [...this.wires, ...this.pipes]) s.attach(c, proxy, gen);
  }

  current(c, gen) {
    return !this.closed && !c.removed && c.generation === gen;
  }

  attachEvent(e, c, proxy, gen) {
    resolveObject(proxy, e.servicePath).then((obj) => {
      if (!this.current(c, gen) || !this.events.has(e)) return;
      if (!obj[e.member]?.on) throw new RRError("RobotRaconteur.MemberNotFound", `no event "${e.member}" on ${obj.$type}`, 9);
      const off = obj[e.member].on((...args) => {
        if (this.current(c, gen) && this.events.has(e)) e.fn(...args, c);
      });
      (e.offs ??= new Map()).set(c, off);
    }).catch((err) => this.current(c, gen) && this.errorListeners.emit(toRRError(err), c));
  }

  attachCallback(cb, c, proxy, gen) {
    resolveObject(proxy, cb.servicePath).then((obj) => {
      if (!this.current(c, gen) || this.callbacks.get(cb.key) !== cb) return;
      if (!obj[cb.member]?.set) throw new RRError("RobotRaconteur.MemberNotFound", `no callback "${cb.member}" on ${obj.$type}`, 9);
      obj[cb.member].set(cb.fn ? (...args) => cb.fn(...args, c) : null);
    }).catch((err) => this.current(c, gen) && this.errorListeners.emit(toRRError(err), c));
  }

  // --- the API ----------------------------------------------------------------------------------------

  /** "connected" (at least one service connected), "connecting" or "closed". */
  get state() {
    if (this.closed) return "closed";
    for (const c of this.clientsById.values()) if (c.state === "connected") return "connected";
    return "connecting";
  }

  /** The matched services, each {id, url, state, proxy, serviceInfo, lastError, connectCount}. */
  get clients() {
    return [...this.clientsById.values()];
  }

  /** Connected clients: id → root object proxy. */
  getConnectedClients() {
    const m = new Map();
    for (const c of this.clientsById.values()) if (c.proxy) m.set(c.id, c.proxy);
    return m;
  }

  /** The first connected service's root proxy, or null. */
  tryGetDefaultClient() {
    for (const c of this.clientsById.values()) if (c.proxy) return c.proxy;
    return null;
  }

  /** The first connected service's root proxy; throws RRError ConnectionError when none is connected. */
  getDefaultClient() {
    const p = this.tryGetDefaultClient();
    if (!p) throw connectionError(this.closed ? "subscription closed" : "no service connected yet");
    return p;
  }

  /** Resolves with the default client once one is connected; rejects with ConnectionError after timeoutMs (−1: never). */
  getDefaultClientWait(timeoutMs = -1) {
    const p = this.tryGetDefaultClient();
    if (p) return Promise.resolve(p);
    if (this.closed) return Promise.reject(connectionError("subscription closed"));
    return new Promise((resolve, reject) => {
      let t = null;
      const w = (proxy, err) => {
        if (t) clearTimeout(t);
        if (err) reject(err);
        else resolve(proxy);
      };
      this.defaultWaiters.push(w);
      if (timeoutMs >= 0) {
        t = setTimeout(() => {
          this.defaultWaiters = this.defaultWaiters.filter((x) => x !== w);
          reject(connectionError(`no service connected within ${timeoutMs} ms`));
        }, timeoutMs);
      }
    });
  }

  /** `fn(client)` as every attempt to connect to a service starts (the first, and each after a drop or a failure). Returns the remover. */
  onConnecting(fn) {
    return this.connectingListeners.add(fn);
  }

  // onConnect(fn(client, proxy)) after every (re)connection; onDisconnect(fn(client, error)) after every
  // lost connection (error null after a clean close); onError(fn(error, client | null)): a failed connect
  // or restore, or a failed discovery request (ConnectionEvents).

  /** A WireSubscription on wire `name` of the object at `servicePath` (relative objref path, "" = root). */
  subscribeWire(name, servicePath = "") {
    this.checkOpen();
    const w = new WireSubscription(this, name, servicePath);
    this.wires.add(w);
    for (const c of this.clientsById.values()) if (c.proxy) w.attach(c, c.proxy, c.generation);
    return w;
  }

  /** A PipeSubscription on pipe `name`; `maxBacklog` packets are kept for receivePacket (−1: no limit). */
  subscribePipe(name, servicePath = "", maxBacklog = 100) {
    this.checkOpen();
    const p = new PipeSubscription(this, name, servicePath, maxBacklog);
    this.pipes.add(p);
    for (const c of this.clientsById.values()) if (c.proxy) p.attach(c, c.proxy, c.generation);
    return p;
  }

  /** `fn(...eventParams, client)` for every firing of event `name` on every connected service; returns the remover. */
  subscribeEvent(name, fn, servicePath = "") {
    this.checkOpen();
    const e = { member: name, fn, servicePath };
    this.events.add(e);
    for (const c of this.clientsById.values()) if (c.proxy) this.attachEvent(e, c, c.proxy, c.generation);
    return () => {
      if (!this.events.delete(e)) return;
      for (const off of e.offs?.values() ?? []) off();
    };
  }

  /** Sets callback `name` on every service, now and after each reconnect (`fn(...params, client)`); null clears it. */
  setCallback(name, fn, servicePath = "") {
    this.checkOpen();
    const key = `${servicePath}\u0000${name}`;
    const cb = { key, member: name, fn, servicePath };
    if (fn) this.callbacks.set(key, cb);
    else this.callbacks.delete(key);
    for (const c of this.clientsById.values()) if (c.proxy) this.attachCallback(cb, c, c.proxy, c.generation);
  }

  checkOpen() {
    if (this.closed) throw new RRError("RobotRaconteur.InvalidOperation", "subscription closed", 17);
  }

  /** Stops reconnecting and closes every connection; resolves once they are closed. */
  async close() {
    if (this.closed) return;
    this.closed = true;
    if (this.discoveryTimer) clearTimeout(this.discoveryTimer);
    for (const w of this.defaultWaiters.splice(0)) w(null, connectionError("subscription closed"));
    for (const s of [...this.wires, ...this.pipes]) {
      s.closeLocal();
      s.ended();
    }
    const closing = [];
    for (const c of this.clientsById.values()) {
      c.removed = true;
      c.wake?.();
      if (c.proxy) closing.push(c.proxy.$client.close().catch(() => {}));
    }
    await Promise.all(closing);
    for (const c of this.clientsById.values()) c.state = "closed";
  }
}

/**
 * Keeps one member connection (a wire connection, a pipe endpoint) per connected client, connecting it
 * again when the service closes it while the client stays connected. Tells its own listeners when a
 * member connection opens, closes or fails to open (onConnect, onDisconnect, onError), so a view can
 * show the state of the one member it shows.
 */
class MemberSubscription extends ConnectionEvents {
  constructor(sub, member, servicePath) {
    super();
    this.sub = sub;
    this.member = member;
    this.servicePath = servicePath;
    this.closed = false;
    this.links = new Map();  // client → connected wire connection / pipe endpoint
  }

  attach(c, proxy, gen, attempt = 0) {
    if (this.closed) return;
    const alive = () => !this.closed && this.sub.current(c, gen);
    resolveObject(proxy, this.servicePath)
      .then((obj) => {
        if (!obj[this.member]?.connect) throw new RRError("RobotRaconteur.MemberNotFound", `no ${this.kind} "${this.member}" on ${obj.$type}`, 9);
        return this.open(obj[this.member]);
      })
      .then((link) => {
        if (!alive()) return link.close().catch(() => {});
        this.links.set(c, link);
        this.listen(link, c);
        this.connectListeners.emit(c);
        link.onClose((err) => {
          if (this.links.get(c) !== link) return;
          this.links.delete(c);
          if (!this.closed) this.disconnectListeners.emit(c, err ? keepable(toRRError(err)) : null);
          // Closed by the service while the connection stays (a device behind the gateway went away):
          // connect it again on this connection. A lost connection is the client loop's business.
          if (!alive() || proxy.$client.state !== "connected") return;
          if (err) this.sub.errorListeners.emit(err, c);
          setTimeout(() => alive() && this.attach(c, proxy, gen, 1), backoffDelay(0, this.sub.backoff));
        });
      })
      .catch((err) => {
        if (!alive() || proxy.$client.state !== "connected") return;
        const e = toRRError(err);
        this.sub.errorListeners.emit(e, c);
        this.errorListeners.emit(keepable(e), c);
        setTimeout(() => alive() && this.attach(c, proxy, gen, attempt + 1), backoffDelay(attempt, this.sub.backoff));
      });
  }

  /** The client's connection is gone (`error`: why): its link died with it. */
  detach(c, error = null) {
    if (this.links.delete(c) && !this.closed) this.disconnectListeners.emit(c, error ? keepable(toRRError(error)) : null);
  }

  // onConnect(fn(client)) each time the member connection to a service opens (first time and after each
  // reconnect); onDisconnect(fn(client, error)) each time an open one closes (error null when closed
  // cleanly); onError(fn(error, client)) each time opening it fails (tried again with backoff): ConnectionEvents.

  closeLocal() {
    this.closed = true;
    const links = [...this.links.values()];
    this.links.clear();
    for (const l of [this.connectListeners, this.disconnectListeners, this.errorListeners]) l.clear();
    return links;
  }

  async close() {
    if (this.closed) return;
    const links = this.closeLocal();
    this.sub[this.kind === "wire" ? "wires" : "pipes"].delete(this);
    this.ended();
    await Promise.all(links.map((l) => l.close().catch(() => {})));
  }

  ended() {}
}

/** WireSubscription: the newest InValue over every connected service's wire connection. */
export class WireSubscription extends MemberSubscription {
  constructor(sub, member, servicePath) {
    super(sub, member, servicePath);
    this.kind = "wire";
    this.latest = null;
    this.valueListeners = new Listeners();
    this.waiters = new Set();
    /** InValue older than this (ms) is not valid (−1: forever). */
    this.inValueLifespanMs = -1;
  }

  open(member) {
    return member.connect();
  }

  listen(conn, c) {
    // A new wire connection starts with the newest value the service (or the gateway) has, which may be
    // the one already delivered from the previous connection: the same sender time stamp from the same
    // service is that value again, not a new one, and is not delivered twice.
    let first = true;
    const take = (value, ts) => {
      if (this.links.get(c) !== conn) return;
      const again = first && this.latest?.client === c && this.latest.ts.seconds === ts.seconds &&
        this.latest.ts.nanoseconds === ts.nanoseconds;
      first = false;
      if (!again) this.deliver(value, ts, c);
    };
    conn.onChange(take);
    if (conn.inValueValid) take(conn.inValue, conn.inValueTime);
  }

  deliver(value, ts, client) {
    if (this.closed) return;
    this.latest = { value, ts, client, at: now() };
    this.valueListeners.emit(value, ts, client);
    for (const w of this.waiters) w(true);
    this.waiters.clear();
  }

  fresh() {
    const l = this.latest;
    if (!l) return null;
    if (this.inValueLifespanMs >= 0 && now() - l.at > this.inValueLifespanMs) return null;
    return l;
  }

  /** The newest InValue from any service; throws RRError ValueNotSet when none is valid. */
  get inValue() {
    const l = this.fresh();
    if (!l) throw new RRError("RobotRaconteur.ValueNotSet", `no valid value on wire "${this.member}"`, 106);
    return l.value;
  }

  /** The sender's time stamp of inValue ({seconds, nanoseconds}); throws like inValue. */
  get inValueTime() {
    this.inValue;  // eslint-disable-line no-unused-expressions
    return this.latest.ts;
  }

  get inValueValid() {
    return this.fresh() !== null;
  }

  /** {value, ts, client} of the newest valid InValue, or undefined. */
  tryGetInValue() {
    const l = this.fresh();
    return l ? { value: l.value, ts: l.ts, client: l.client } : undefined;
  }

  /** Resolves true once an InValue is valid, false after timeoutMs (−1: wait as long as it takes). */
  waitInValueValid(timeoutMs = -1) {
    if (this.inValueValid) return Promise.resolve(true);
    if (this.closed) return Promise.resolve(false);
    return new Promise((resolve) => {
      let t = null;
      const w = (ok) => {
        if (t) clearTimeout(t);
        this.waiters.delete(w);
        resolve(ok);
      };
      this.waiters.add(w);
      if (timeoutMs >= 0) t = setTimeout(() => w(false), timeoutMs);
    });
  }

  /** `fn(value, ts, client)` for every new InValue from any service; returns the remover. */
  onValueChanged(fn) {
    return this.valueListeners.add(fn);
  }

  /** Wire connections open now (one per connected service that has the wire). */
  get activeWireConnectionCount() {
    return this.links.size;
  }

  /** Sets the OutValue on every wire connection open now (a value that does not fit throws RRError). */
  setOutValueAll(value) {
    for (const conn of this.links.values()) conn.outValue = value;
  }

  ended() {
    this.valueListeners.clear();
    for (const w of this.waiters) w(false);
  }
}

/** PipeSubscription: packets from one pipe endpoint per connected service. */
export class PipeSubscription extends MemberSubscription {
  constructor(sub, member, servicePath, maxBacklog) {
    super(sub, member, servicePath);
    if (!Number.isInteger(maxBacklog) || maxBacklog < -1) throw invalid(`maxBacklog must be an integer >= -1, not ${maxBacklog}`);
    this.kind = "pipe";
    this.maxBacklog = maxBacklog;
    this.queue = [];
    this.packetListeners = new Listeners();
    this.receivers = [];
  }

  open(member) {
    return member.connect(-1);
  }

  listen(ep, c) {
    ep.onPacket((packet) => {
      if (this.links.get(c) === ep) this.deliver(packet, c);
    });
  }

  deliver(packet, client) {
    if (this.closed) return;
    this.packetListeners.emit(packet, client);
    const r = this.receivers.shift();
    if (r) return r(packet);
    if (this.maxBacklog === 0) return;
    this.queue.push(packet);
    if (this.maxBacklog > 0 && this.queue.length > this.maxBacklog) this.queue.shift();  // the oldest goes
  }

  /** Packets waiting in the backlog. */
  get available() {
    return this.queue.length;
  }

  /** The oldest queued packet, or undefined. */
  tryReceivePacket() {
    return this.queue.shift();
  }

  /** The next packet: at once when one is queued, else when one comes; undefined after timeoutMs (−1: wait). */
  receivePacket(timeoutMs = -1) {
    if (this.queue.length) return Promise.resolve(this.queue.shift());
    if (this.closed) return Promise.resolve(undefined);
    return new Promise((resolve) => {
      let t = null;
      const r = (p) => {
        if (t) clearTimeout(t);
        resolve(p);
      };
      this.receivers.push(r);
      if (timeoutMs >= 0) {
        t = setTimeout(() => {
          this.receivers = this.receivers.filter((x) => x !== r);
          resolve(undefined);
        }, timeoutMs);
      }
    });
  }

  /** `fn(packet, client)` for every packet from any service; returns the remover. */
  onPacketReceived(fn) {
    return this.packetListeners.add(fn);
  }

  /** Pipe endpoints open now. */
  get activePipeEndpointCount() {
    return this.links.size;
  }

  /** Sends `packet` on every endpoint open now; resolves once all are sent. */
  sendPacketAll(packet) {
    return Promise.all([...this.links.values()].map((ep) => ep.send(packet)));
  }

  ended() {
    this.packetListeners.clear();
    for (const r of this.receivers.splice(0)) r(undefined);
  }

  [Symbol.asyncIterator]() {
    return {
      next: () => this.receivePacket().then((value) => (value === undefined && this.closed ? { value, done: true } : { value, done: false })),
      return: () => this.close().then(() => ({ value: undefined, done: true })),
    };
  }
}

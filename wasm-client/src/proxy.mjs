// Object proxies: one JS object per RR object, with one entry per member, shaped by the member kind
// (README.md "API"). Every network call goes through Connection.op (a Promise) or Connection.sync.
import { RRError, toRRError } from "./errors.mjs";
// later(): user code runs outside the native call stack; its errors are reported, never thrown into C++.
import { later } from "./backoff.mjs";

const now = () => performance.now();

/** A queue that async iterators wait on. */
class AsyncQueue {
  constructor() {
    this.items = [];
    this.waiters = [];
    this.ended = null;
  }
  push(x) {
    const w = this.waiters.shift();
    if (w) w.resolve({ value: x, done: false });
    else this.items.push(x);
  }
  end(error) {
    this.ended = { error };
    for (const w of this.waiters.splice(0)) error ? w.reject(error) : w.resolve({ value: undefined, done: true });
  }
  next() {
    if (this.items.length) return Promise.resolve({ value: this.items.shift(), done: false });
    if (this.ended) return this.ended.error ? Promise.reject(this.ended.error) : Promise.resolve({ value: undefined, done: true });
    return new Promise((resolve, reject) => this.waiters.push({ resolve, reject }));
  }
}

const CONNECTION = Symbol("connection");
function definitionsOf() {
  return this[CONNECTION].definitions;
}

export function makeProxy(conn, desc) {
  const proxy = {
    $type: desc.type,
    $path: desc.path,
    $implements: desc.implements,
    $members: desc.members,
    $client: conn.clientApi,
    /** Monitor lock of this object (`timeoutMs` −1: wait as long as it takes). */
    $monitorEnter: (timeoutMs = -1) => conn.op((cb) => conn.native.monitor(desc.path, true, timeoutMs, now(), cb)),
    $monitorExit: () => conn.op((cb) => conn.native.monitor(desc.path, false, 0, now(), cb)),
  };
  // One getter shared by every proxy, reading the connection from a hidden slot: V8 keeps an accessor in
  // the object's hidden class, and a closure over `conn` there would keep a closed connection alive.
  Object.defineProperty(proxy, CONNECTION, { value: conn });
  Object.defineProperty(proxy, "$definitions", { get: definitionsOf, enumerable: true });
  const members = new Map();
  for (const m of desc.members) {
    const make = MEMBER_KINDS[m.kind];
    if (!make) continue;
    const member = make(conn, desc.path, m);
    members.set(m.name, member);
    // A property named `then` would make the proxy a thenable: `await proxy`, or a promise resolved
    // with it (connect(), objref get()), would call it and wait forever. Such a member is reached
    // with proxy.$member("then") only (README "API").
    if (!NOT_A_PROPERTY.has(m.name)) proxy[m.name] = member;
  }
  /** The member `name` (every member, also one that is not a property of the proxy, such as `then`). */
  proxy.$member = (name) => {
    const member = members.get(name);
    if (member === undefined) throw new RRError("RobotRaconteur.MemberNotFound", `${desc.type} has no member "${name}"`, 9);
    return member;
  };
  return proxy;
}

/** Member names that are never properties of a proxy (reached with $member). */
const NOT_A_PROPERTY = new Set(["then"]);

const MEMBER_KINDS = {
  property: (conn, path, m) => ({
    get: () => conn.op((cb) => conn.native.propertyGet(path, m.name, now(), cb)),
    set: (v) => conn.op((cb) => conn.native.propertySet(path, m.name, v, now(), cb)),
  }),

  function: (conn, path, m) => {
    if (m.generator) {
      return (...args) =>
        conn.op((cb) => conn.native.callGenerator(path, m.name, args, now(), cb)).then((id) => new Generator(conn, id));
    }
    return (...args) => conn.op((cb) => conn.native.call(path, m.name, args, now(), cb));
  },

  event: (conn, path, m) => ({
    /** Calls `fn(...params)` for every event; returns the function that unsubscribes. */
    on(fn) {
      const id = conn.sync((n) => n.subscribeEvent(path, m.name, (args) => later(fn, ...args)));
      let on = true;
      return () => {
        if (!on) return;
        on = false;
        if (!conn.deleted) conn.native.unsubscribeEvent(id);
      };
    },
  }),

  objref: (conn, path, m) => ({
    /** The object behind the objref (`index`: int32 or string for indexed objrefs). */
    get: (index) =>
      conn.op((cb) => conn.native.objref(path, m.name, index ?? null, now(), cb)).then((o) => conn.proxy(o.path)),
  }),

  callback: (conn, path, m) => ({
    /** Sets the handler (may be async; its result or thrown RRError goes back to the service); null clears it. */
    set(fn) {
      if (!fn) return conn.sync((n) => n.setCallback(path, m.name, null));
      return conn.sync((n) =>
        n.setCallback(path, m.name, (args, replyId) =>
          queueMicrotask(async () => {
            let error = null;
            let value;
            try {
              value = await fn(...args);
            } catch (e) {
              error = {
                name: e instanceof RRError ? e.errorName : "RobotRaconteur.OperationFailed",
                message: String(e?.message ?? e),
              };
            }
            if (conn.deleted) return;
            conn.native.callbackReply(replyId, error, value === undefined ? null : value);
            conn.scheduleFlush();
          }),
        ),
      );
    },
  }),

  pipe: (conn, path, m) => ({
    /** Connects a pipe endpoint (`index` −1: the service chooses). */
    connect: (index = -1) =>
      conn.op((cb) => conn.native.pipeConnect(path, m.name, index, now(), cb)).then((r) => new PipeEndpoint(conn, r)),
  }),

  wire: (conn, path, m) => ({
    connect: () => conn.op((cb) => conn.native.wireConnect(path, m.name, now(), cb)).then((id) => new WireConnection(conn, id)),
    peekInValue: () => conn.op((cb) => conn.native.wirePeek(path, m.name, true, now(), cb)).then((w) => w.value),
    peekOutValue: () => conn.op((cb) => conn.native.wirePeek(path, m.name, false, now(), cb)).then((w) => w.value),
    /** {value, ts: {seconds, nanoseconds}} */
    peekInValueWithTime: () => conn.op((cb) => conn.native.wirePeek(path, m.name, true, now(), cb)),
    pokeOutValue: (v) => conn.op((cb) => conn.native.wirePoke(path, m.name, v, Date.now(), now(), cb)),
  }),

  memory: (conn, path, m) => ({
    /** Items of an array memory. */
    length: () => conn.op((cb) => conn.native.memoryParam(path, m.name, "length", now(), cb)),
    /** Dimensions of a multi-dim memory. */
    dimensions: () => conn.op((cb) => conn.native.memoryParam(path, m.name, "dimensions", now(), cb)),
    dimCount: () => conn.op((cb) => conn.native.memoryParam(path, m.name, "dimcount", now(), cb)),
    /** Array memory: read(start, count); multi-dim: read([start…], [count…]) → {dims, array}. */
    read: (start, count) => conn.op((cb) => conn.native.memoryRead(path, m.name, start, count, now(), cb)),
    write: (start, data) => conn.op((cb) => conn.native.memoryWrite(path, m.name, start, data, now(), cb)),
  }),
};

/** A generator returned by a generator function. */
class Generator {
  constructor(conn, id) {
    this.conn = conn;
    this.id = id;
    this.done = false;
  }
  /** The next value (`param` for generators with a generator parameter); rejects with StopIteration at the end. */
  next(param) {
    if (this.done) return Promise.reject(new RRError("RobotRaconteur.StopIteration", "generator finished", 109));
    return this.conn.op((cb) => this.conn.native.generatorNext(this.id, param ?? null, now(), cb)).catch((e) => {
      if (e.errorName === "RobotRaconteur.StopIteration" || e.errorName === "RobotRaconteur.InvalidOperation") this.done = true;
      throw e;
    });
  }
  close() {
    return this.finish(false);
  }
  abort() {
    return this.finish(true);
  }
  finish(abort) {
    if (this.done) return Promise.resolve();
    this.done = true;
    return this.conn.op((cb) => this.conn.native.generatorClose(this.id, abort, now(), cb));
  }
  [Symbol.asyncIterator]() {
    return {
      next: () =>
        this.next().then(
          (value) => ({ value, done: false }),
          (e) => {
            if (e.errorName === "RobotRaconteur.StopIteration") return { value: undefined, done: true };
            throw e;
          },
        ),
      return: () => this.close().then(() => ({ value: undefined, done: true })),
    };
  }
}

/** A connected pipe endpoint. Packets go to onPacket listeners and to async iteration / receive(). */
class PipeEndpoint {
  constructor(conn, r) {
    this.conn = conn;
    this.id = r.id;
    this.index = r.index;
    this.closed = false;
    this.listeners = new Set();
    this.closeListeners = new Set();
    this.acks = new Set();
    this.queue = new AsyncQueue();
    conn.sync((n) =>
      n.pipeSetHandlers(
        this.id,
        () => this.drain(),
        (num) => later(() => this.acks.forEach((fn) => fn(num))),
        (err) => this.onClosed(toRRError(err)),
      ),
    );
    conn.closeListeners.add((this.connClosed = (e) => this.onClosed(e)));
    this.drain();  // packets that arrived with the connect reply, before the handlers were set
  }
  drain() {
    for (;;) {
      const r = this.conn.native.pipeReceive(this.id);
      if (!r.ok || r.value === undefined) break;
      const pkt = r.value.packet;
      if (this.listeners.size) for (const fn of this.listeners) later(fn, pkt);
      else this.queue.push(pkt);
    }
  }
  onClosed(error) {
    if (this.closed) return;
    this.closed = true;
    this.conn.closeListeners.delete(this.connClosed);
    this.queue.end();
    for (const fn of this.closeListeners) later(fn, error);
  }
  /** `fn(packet)` for every packet received (and those queued so far); returns the function that removes it. */
  onPacket(fn) {
    this.listeners.add(fn);
    for (const pkt of this.queue.items.splice(0)) later(fn, pkt);
    return () => this.listeners.delete(fn);
  }
  onClose(fn) {
    this.closeListeners.add(fn);
    return () => this.closeListeners.delete(fn);
  }
  onAck(fn) {
    this.acks.add(fn);
    return () => this.acks.delete(fn);
  }
  /** The next packet (waits); resolves undefined once the endpoint is closed. */
  receive() {
    return this.queue.next().then((r) => r.value);
  }
  /** Sends a packet; resolves with its packet number. */
  async send(v) {
    return this.conn.sync((n) => n.pipeSend(this.id, v, now()));
  }
  close() {
    if (this.closed) return Promise.resolve();
    const p = this.conn.op((cb) => this.conn.native.pipeClose(this.id, now(), cb));
    this.onClosed(null);
    return p;
  }
  [Symbol.asyncIterator]() {
    return { next: () => this.queue.next(), return: () => this.close().then(() => ({ value: undefined, done: true })) };
  }
}

/** A connected wire connection. */
class WireConnection {
  constructor(conn, id) {
    this.conn = conn;
    this.id = id;
    this.closed = false;
    this.listeners = new Set();
    this.closeListeners = new Set();
    this.lifespan = -1;
    this.waiters = [];
    conn.sync((n) =>
      n.wireSetHandlers(
        id,
        (w) => {
          for (const fn of this.listeners) later(fn, w.value, w.ts);
          for (const r of this.waiters.splice(0)) r(w.value);
        },
        (err) => this.onClosed(toRRError(err)),
      ),
    );
    conn.closeListeners.add((this.connClosed = (e) => this.onClosed(e)));
  }
  onClosed(error) {
    if (this.closed) return;
    this.closed = true;
    this.conn.closeListeners.delete(this.connClosed);
    for (const fn of this.closeListeners) later(fn, error);
  }
  /** The newest InValue; throws RRError ValueNotSet when none arrived (or it is older than the lifespan). */
  get inValue() {
    return this.conn.sync((n) => n.wireInValue(this.id, now())).value;
  }
  /** Sender's time stamp of the InValue: {seconds, nanoseconds} since 1970-01-01 UTC. */
  get inValueTime() {
    return this.conn.sync((n) => n.wireInValue(this.id, now())).ts;
  }
  get inValueValid() {
    try {
      this.conn.sync((n) => n.wireInValue(this.id, now()));
      return true;
    } catch {
      return false;
    }
  }
  get outValue() {
    return this.conn.sync((n) => n.wireOutValue(this.id, now())).value;
  }
  get outValueTime() {
    return this.conn.sync((n) => n.wireOutValue(this.id, now())).ts;
  }
  /** Sends a new OutValue (throws RRError for a value that does not match the robdef). */
  set outValue(v) {
    this.conn.sync((n) => n.wireSetOutValue(this.id, v, Date.now(), now()));
  }
  /** Lifespan of InValue and OutValue in ms (−1 = forever). */
  get lifespanMs() {
    return this.lifespan;
  }
  set lifespanMs(ms) {
    this.conn.sync((n) => n.wireSetLifespans(this.id, ms, ms));
    this.lifespan = ms;
  }
  /** Resolves with the InValue once one is there (at once when valid). */
  waitInValue(timeoutMs = 5000) {
    try {
      return Promise.resolve(this.inValue);
    } catch {
      // none yet: wait for the next value
    }
    return new Promise((resolve, reject) => {
      const t = setTimeout(() => reject(new RRError("RobotRaconteur.ValueNotSet", "no wire value in time", 106)), timeoutMs);
      this.waiters.push((v) => {
        clearTimeout(t);
        resolve(v);
      });
    });
  }
  /** `fn(value, ts)` for every newer InValue; returns the function that removes it. */
  onChange(fn) {
    this.listeners.add(fn);
    return () => this.listeners.delete(fn);
  }
  onClose(fn) {
    this.closeListeners.add(fn);
    return () => this.closeListeners.delete(fn);
  }
  close() {
    if (this.closed) return Promise.resolve();
    const p = this.conn.op((cb) => this.conn.native.wireClose(this.id, now(), cb));
    this.onClosed(null);
    return p;
  }
}

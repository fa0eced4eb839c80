// Reconnect delays shared by the RR subscriptions (subscription.mjs) and the JSON client (json_client.mjs),
// and the listener helpers they and the proxies (proxy.mjs) share.
import { RRError } from "./errors.mjs";

/** Defaults: 0.5 s, doubling up to 10 s, each delay spread ±25 % (README.md "Subscriptions"). */
export const DEFAULT_BACKOFF = Object.freeze({ initialMs: 500, maxMs: 10000, factor: 2, jitter: 0.25 });

/** After a server closed with 1001 Going Away (it is stopping, likely to restart), attempts this long
 * after the close keep the first backoff delay instead of growing it. */
export const GOING_AWAY_WINDOW_MS = 15000;

/**
 * Checks and completes a backoff option `{initialMs, maxMs, factor, jitter}` (any field may be left out).
 * Throws RRError InvalidArgument for a field out of range.
 */
export function backoffOptions(b = {}) {
  const r = { ...DEFAULT_BACKOFF, ...b };
  const bad = (why) => {
    throw new RRError("RobotRaconteur.InvalidArgument", `backoff: ${why}`, 18);
  };
  if (!(Number.isFinite(r.initialMs) && r.initialMs >= 0)) bad(`initialMs must be a number >= 0, not ${r.initialMs}`);
  if (!(Number.isFinite(r.maxMs) && r.maxMs >= r.initialMs)) bad(`maxMs must be a number >= initialMs, not ${r.maxMs}`);
  if (!(Number.isFinite(r.factor) && r.factor >= 1)) bad(`factor must be a number >= 1, not ${r.factor}`);
  if (!(Number.isFinite(r.jitter) && r.jitter >= 0 && r.jitter <= 1)) bad(`jitter must be in [0, 1], not ${r.jitter}`);
  return r;
}

/**
 * The delay in ms before reconnect attempt `attempt` (0 for the first after a drop):
 * base = min(maxMs, initialMs · factor^attempt), drawn uniformly from [base·(1−jitter), base·(1+jitter)]
 * so that many clients cut off together do not come back in step.
 */
export function backoffDelay(attempt, b, random = Math.random) {
  const base = Math.min(b.maxMs, b.initialMs * b.factor ** Math.min(attempt, 64));
  return Math.max(0, Math.round(base * (1 - b.jitter + 2 * b.jitter * random())));
}

/** Calls `fn(...args)` in a microtask; an exception or rejection is logged, never thrown at the caller. */
export function later(fn, ...args) {
  queueMicrotask(() => {
    try {
      const r = fn(...args);
      if (r && typeof r.catch === "function") r.catch((e) => console.error(e));
    } catch (e) {
      console.error(e);
    }
  });
}

/** A set of listeners: add(fn) returns the remover; emit(...args) calls each in a microtask. */
export class Listeners {
  constructor() {
    this.fns = new Set();
  }
  add(fn) {
    if (typeof fn !== "function") throw new RRError("RobotRaconteur.InvalidArgument", "a listener must be a function", 18);
    // A wrapper per add, so that adding one function twice gives two independent removers.
    const entry = (...a) => fn(...a);
    this.fns.add(entry);
    return () => this.fns.delete(entry);
  }
  emit(...args) {
    for (const fn of this.fns) later(fn, ...args);
  }
  get size() {
    return this.fns.size;
  }
  clear() {
    this.fns.clear();
  }
}

/**
 * The three connection events of a reconnecting thing (a subscription, a member connection of it, the
 * JSON client): what `fn` gets is each class's own (its docs say). `onConnect`, `onDisconnect` and
 * `onError` return the remover.
 */
export class ConnectionEvents {
  constructor() {
    this.connectListeners = new Listeners();
    this.disconnectListeners = new Listeners();
    this.errorListeners = new Listeners();
  }
  onConnect(fn) {
    return this.connectListeners.add(fn);
  }
  onDisconnect(fn) {
    return this.disconnectListeners.add(fn);
  }
  onError(fn) {
    return this.errorListeners.add(fn);
  }
}

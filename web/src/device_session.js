// The one place that knows the state of this page's RR session to a device through the gateway
// (rr+ws://<gateway>/<page's folder>?service=<device>): a subscription of the client package
// (vendor/rr/robotraconteur.mjs `subscribe`, wasm-client/src/subscription.mjs) keeps it up with the
// package's reconnect policy (its jittered backoff, 0.5 s doubling to 5 s here), and every view of the
// device subscribes its wires, pipes and events through that same subscription (`subscription`, and
// views/live_object.js), so a fix to reconnecting is made in the package alone.
//
// A device with logins of its own behind an `auth: passthrough` gateway device (docs/security.md "Logins
// and locks through the gateway") refuses a connect without the right credentials with
// RobotRaconteur.AuthenticationError. Retrying cannot help then, so the session closes its subscription
// and waits in state "login" until login(username, password) (or stop()); the credentials live in this
// object only.
//
// Events (EventTarget): "state" with detail { state: "connecting" | "connected" | "closed" | "login" |
// "stopped", client (the root proxy, when connected), attempt (when connecting: attempts so far), error
// (why the last attempt failed or the session ended; for "login" the device's refusal, or null after
// logout()) }.

/** The package's backoff, capped lower than its default: a person watches this page. */
const BACKOFF = { maxMs: 5000 };
const CONNECT_TIMEOUT_MS = 15000;
/** A client package that failed to load (not deployed yet) is asked for again after this long. */
const PACKAGE_RETRY_MS = 5000;

let rrModule = null;
/** The client package, loaded once (a missing package is reported as the connect error). */
export function loadClientPackage() {
  rrModule ??= import("../vendor/rr/robotraconteur.mjs").catch((e) => {
    rrModule = null; // try again next time (the package may be deployed later)
    throw e;
  });
  return rrModule;
}

/**
 * The RR URL of device `name` on the gateway that served this page, relative to the page: the page's
 * folder keeps a reverse proxy's path prefix (a page at https://site/rr/ connects to
 * rr+wss://site/rr/?service=name), so `location /rr/ { proxy_pass http://gateway/; }` is all a proxy
 * needs (docs/deployment.md). The hash (#/device) and the page's query are not part of it.
 */
export function deviceUrl(name, loc = window.location) {
  const scheme = loc.protocol === "https:" ? "rr+wss" : "rr+ws";
  const folder = new URL(".", `${loc.protocol}//${loc.host}${loc.pathname}`).pathname;
  return `${scheme}://${loc.host}${folder}?service=${encodeURIComponent(name)}`;
}

/** True for the device's refusal of a login (a missing, unknown or wrong user or password). */
export function isAuthenticationError(e) {
  return e?.errorName === "RobotRaconteur.AuthenticationError";
}

export class DeviceSession extends EventTarget {
  /**
   * @param {string} url  the device's RR URL on the gateway
   * @param {object} [options]  credentials: { username, password } to connect with (null: none);
   *   subscribe: the client package's subscribe(url, options) (tests pass their own)
   */
  constructor(url, options = {}) {
    super();
    this.url = url;
    this.credentials = options.credentials ?? null;
    this.subscribeImpl = options.subscribe ?? null;
    this.stopped = false;
    /** The root object proxy while connected, else null. */
    this.client = null;
    /** The subscription now in use (a new one after each login and logout), null while none is. */
    this.subscription = null;
    this.needLogin = false;
    this.attempts = 0;
    this.retryTimer = 0;
  }

  /** The user this session logs in as, or null without credentials. */
  get username() { return this.credentials?.username ?? null; }

  emit(state, extra = {}) {
    this.state = state;
    this.dispatchEvent(new CustomEvent("state", { detail: { state, ...extra } }));
  }

  /** Starts the session (once); `loop` resolves once it has stopped. */
  start() {
    if (!this.loop) {
      this.loop = new Promise((resolve) => { this.finished = resolve; });
      this.open();
    }
    return this;
  }

  /** Replaces the subscription by a new one with the current credentials (none while a login is awaited). */
  async open() {
    this.drop();
    if (this.stopped) return;
    if (this.needLogin) { this.emit("login", { error: null }); return; }
    let subscribe = this.subscribeImpl;
    if (!subscribe) {
      try {
        subscribe = (await loadClientPackage()).subscribe;
      } catch (e) {
        if (this.stopped || this.subscription) return;
        this.emit("closed", { error: e });
        this.retryTimer = setTimeout(() => this.open(), PACKAGE_RETRY_MS);
        return;
      }
      if (this.stopped || this.subscription) return;
    }
    const sub = subscribe(this.url, { timeoutMs: CONNECT_TIMEOUT_MS, backoff: BACKOFF, ...(this.credentials ?? {}) });
    this.subscription = sub;
    const mine = (fn) => (...args) => { if (this.subscription === sub && !this.stopped) fn(...args); };
    // The subscription's events come in the order they happened: an error between an attempt's start
    // and its connection is that attempt's failure; any other (a wire's, an event's) is its view's.
    let attempting = false;
    sub.onConnecting(mine(() => {
      attempting = true;
      this.emit("connecting", { attempt: ++this.attempts });
    }));
    sub.onConnect(mine((c, proxy) => {
      attempting = false;
      this.client = proxy;
      this.emit("connected", { client: proxy });
    }));
    sub.onDisconnect(mine((c, error) => {
      this.client = null;
      this.emit("closed", { error: error ?? "session closed" });
    }));
    sub.onError(mine((error) => {
      if (!attempting) return;
      attempting = false;
      if (isAuthenticationError(error)) {
        this.drop();
        this.emit("login", { error });
        return;
      }
      this.emit("closed", { error });
    }));
  }

  /** Closes the subscription now in use (its events no longer count). */
  drop() {
    clearTimeout(this.retryTimer);
    const sub = this.subscription;
    this.subscription = null;
    this.client = null;
    sub?.close().catch(() => {});
  }

  /** Connects again at once when the session is waiting to (e.g. the gateway reports the device back); not a wait for a login. */
  retryNow() {
    if (this.state === "closed" && !this.stopped) this.open();
  }

  /** Connects (again) as `username` with `password`: ends a wait for a login, or replaces the session. */
  login(username, password) {
    this.credentials = { username, password };
    this.needLogin = false;
    this.open();
  }

  /** Forgets the credentials and closes the session; it then waits for login() without connecting. */
  logout() {
    this.credentials = null;
    this.needLogin = true;
    this.open();
  }

  /** Closes the session and stops reconnecting. */
  stop() {
    if (this.stopped) return;
    this.stopped = true;
    this.drop();
    this.emit("stopped");
    this.finished?.();
  }
}

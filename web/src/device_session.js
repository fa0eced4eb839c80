// One browser RR session to a device through the gateway (rr+ws://<gateway>/<page's folder>?service=<device>), made
// with the client package (vendor/rr/robotraconteur.mjs) and kept up: after a failed connect or a
// close it connects again with backoff (0.5 s doubling to 5 s).
//
// A device with logins of its own behind an `auth: passthrough` gateway device (docs/security.md "Logins
// and locks through the gateway") refuses a connect without the right credentials with
// RobotRaconteur.AuthenticationError. Retrying cannot help then, so the loop waits in state "login"
// until login(username, password) (or stop()); the credentials live in this object only.
//
// Events (EventTarget): "state" with detail { state: "connecting" | "connected" | "closed" | "login" |
// "stopped", client (when connected), error (why the last attempt failed or the session ended; for
// "login" the device's refusal, or null after logout()) }.

const BACKOFF_MIN_MS = 500;
const BACKOFF_MAX_MS = 5000;
const CONNECT_TIMEOUT_MS = 15000;

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
   *   connect: the client package's connect (tests pass their own)
   */
  constructor(url, options = {}) {
    super();
    this.url = url;
    this.credentials = options.credentials ?? null;
    this.connectImpl = options.connect ?? null;
    this.stopped = false;
    this.client = null;
    this.wake = null;
    this.loginWait = null;
    this.needLogin = false;
    this.attempts = 0;
  }

  /** The user this session logs in as, or null without credentials. */
  get username() { return this.credentials?.username ?? null; }

  emit(state, extra = {}) {
    this.state = state;
    this.dispatchEvent(new CustomEvent("state", { detail: { state, ...extra } }));
  }

  /** Starts the connect loop (once). */
  start() {
    if (!this.loop) this.loop = this.run();
    return this;
  }

  /** Ends a waiting backoff now (e.g. the gateway reports the device back); not a wait for a login. */
  retryNow() { this.wake?.(); }

  /** Connects (again) as `username` with `password`: ends a wait for a login, or replaces the session. */
  login(username, password) {
    this.credentials = { username, password };
    this.needLogin = false;
    if (this.loginWait) this.loginWait();
    else this.reopen();
  }

  /** Forgets the credentials and closes the session; the loop then waits for login() without connecting. */
  logout() {
    this.credentials = null;
    this.needLogin = true;
    this.reopen();
  }

  reopen() {
    this.wake?.();
    try { this.client?.$client.close(); } catch { /* already closed */ }
  }

  /** Waits in state "login" (no retries) until login() or stop(). */
  async waitForLogin(error) {
    this.emit("login", { error });
    await new Promise((resolve) => { this.loginWait = resolve; });
    this.loginWait = null;
  }

  async run() {
    let backoff = BACKOFF_MIN_MS;
    while (!this.stopped) {
      if (this.needLogin) {
        await this.waitForLogin(null);
        continue;
      }
      this.attempts++;
      this.emit("connecting", { attempt: this.attempts });
      let error = null;
      const used = this.credentials;
      // login() or logout() while this attempt was under way: its result no longer counts.
      const superseded = () => this.needLogin || this.credentials !== used;
      try {
        const connect = this.connectImpl ?? (await loadClientPackage()).connect;
        const c = await connect(this.url, { timeoutMs: CONNECT_TIMEOUT_MS, ...(used ?? {}) });
        if (this.stopped) { c.$client.close(); break; }
        if (superseded()) { c.$client.close(); continue; }
        backoff = BACKOFF_MIN_MS;
        this.client = c;
        const closed = new Promise((resolve) => c.$client.onClose((why) => resolve(why)));
        this.emit("connected", { client: c });
        error = await closed;
        this.client = null;
        if (this.stopped) break;
        // login() and logout() close the session on purpose: connect again at once (or wait for a login).
        if (superseded()) continue;
        this.emit("closed", { error: error ?? "session closed" });
      } catch (e) {
        if (this.stopped) break;
        if (superseded()) continue;
        if (isAuthenticationError(e)) {
          backoff = BACKOFF_MIN_MS;
          await this.waitForLogin(e);
          continue;
        }
        error = e;
        this.emit("closed", { error: e });
      }
      await new Promise((resolve) => {
        this.wake = resolve;
        setTimeout(resolve, backoff);
      });
      this.wake = null;
      backoff = Math.min(backoff * 2, BACKOFF_MAX_MS);
    }
    this.emit("stopped");
  }

  /** Closes the session and stops reconnecting. */
  stop() {
    this.stopped = true;
    this.wake?.();
    this.loginWait?.();
    try { this.client?.$client.close(); } catch { /* already closed */ }
  }
}

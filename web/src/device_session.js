// One browser RR session to a device through the gateway (rr+ws://<gateway>/<page's folder>?service=<device>), made
// with the client package (vendor/rr/robotraconteur.mjs) and kept up: after a failed connect or a
// close it connects again with backoff (0.5 s doubling to 5 s).
//
// Events (EventTarget): "state" with detail { state: "connecting" | "connected" | "closed" | "stopped",
// client (when connected), error (why the last attempt failed or the session ended) }.

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

export class DeviceSession extends EventTarget {
  constructor(url) {
    super();
    this.url = url;
    this.stopped = false;
    this.client = null;
    this.wake = null;
    this.attempts = 0;
  }

  emit(state, extra = {}) {
    this.state = state;
    this.dispatchEvent(new CustomEvent("state", { detail: { state, ...extra } }));
  }

  /** Starts the connect loop (once). */
  start() {
    if (!this.loop) this.loop = this.run();
    return this;
  }

  /** Ends a waiting backoff now (e.g. the gateway reports the device back). */
  retryNow() { this.wake?.(); }

  async run() {
    let backoff = BACKOFF_MIN_MS;
    while (!this.stopped) {
      this.attempts++;
      this.emit("connecting", { attempt: this.attempts });
      let error = null;
      try {
        const { connect } = await loadClientPackage();
        const c = await connect(this.url, { timeoutMs: CONNECT_TIMEOUT_MS });
        if (this.stopped) { c.$client.close(); break; }
        backoff = BACKOFF_MIN_MS;
        this.client = c;
        const closed = new Promise((resolve) => c.$client.onClose((why) => resolve(why)));
        this.emit("connected", { client: c });
        error = await closed;
        this.client = null;
        if (this.stopped) break;
        this.emit("closed", { error: error ?? "session closed" });
      } catch (e) {
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
    try { this.client?.$client.close(); } catch { /* already closed */ }
  }
}

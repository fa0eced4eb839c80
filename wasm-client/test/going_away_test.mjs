// A subscription whose connection the server closed with 1001 Going Away (a gateway stopping for a
// restart) tries again at the first backoff delay; after any other drop (1006: a crash, a cut network)
// the delays grow as before. Fake connections (subscribe()'s connect function is injected), and the
// delays read from the timers the subscription sets: no waiting on the clock, no WebAssembly needed.
// Usage: node going_away_test.mjs
import { ServiceSubscription } from "../src/subscription.mjs";
import { RRError } from "../src/errors.mjs";

let failures = 0;
const ok = (cond, what) => { console.log(`${cond ? "ok" : "FAIL"}: ${what}`); if (!cond) failures++; };

// Every setTimeout delay the subscription asks for; the backoff sleeps are the ones >= 1 ms.
const delays = [];
const realSetTimeout = globalThis.setTimeout;
globalThis.setTimeout = (fn, ms, ...args) => {
  delays.push(ms);
  return realSetTimeout(fn, Math.min(ms ?? 0, 5), ...args);  // run soon: the test reads the delays, not the clock
};

/** A fake service: connect() answers from `script` (true: a connection, false: refused). */
function fakeService() {
  const s = { attempts: 0, refuse: 0, open: null, connected: null };
  s.connect = async () => {
    s.attempts++;
    if (s.refuse > 0) {
      s.refuse--;
      throw new RRError("RobotRaconteur.ConnectionError", "connection refused", 1);
    }
    const closeListeners = new Set();
    const client = {
      closeCode: null,
      onClose: (fn) => { closeListeners.add(fn); return () => closeListeners.delete(fn); },
      close: async () => {},
    };
    const proxy = { $client: client, $members: [], $type: "fake.Root" };
    s.open = {
      drop(code) {
        client.closeCode = code;
        for (const fn of closeListeners) fn(new RRError("RobotRaconteur.ConnectionError", `WebSocket closed (code ${code})`, 1));
      },
    };
    return proxy;
  };
  return s;
}

async function dropAndCount(code) {
  const svc = fakeService();
  // jitter 0: the delays are exact; factor 1000: a second failed attempt would wait 1000x the first
  const sub = new ServiceSubscription("rr+ws://fake/?service=x", { backoff: { initialMs: 10, maxMs: 1e7, factor: 1000, jitter: 0 } }, svc.connect);
  // the subscription's own event: the connection is up and watched
  let connected;
  sub.onConnect(() => connected?.());
  const nextConnect = () => new Promise((r) => { connected = r; });
  await nextConnect();
  svc.refuse = 3;  // the server is away for three attempts
  delays.length = 0;
  const back = nextConnect();
  svc.open.drop(code);
  if (code === 1001) {
    await back;  // every attempt at the first delay: back after three refusals
    const sleeps = delays.filter((d) => d >= 1);
    ok(sleeps.length >= 4 && sleeps.slice(0, 4).every((d) => d === 10),
      `after 1001 Going Away: attempts at the first delay (${sleeps.slice(0, 4).join(", ")} ms), connected again`);
  } else {
    // after a 1006 the sleeps grow (10, 10 000, 10 000 000 ms): the first connection and three refused
    // attempts are four connect calls; the third refusal's sleep is the last one checked
    while (svc.attempts < 4 || delays.filter((d) => d >= 1).length < 4) await new Promise((r) => realSetTimeout(r, 1));
    const sleeps = delays.filter((d) => d >= 1);
    ok(sleeps[0] === 10 && sleeps[1] === 10000 && sleeps[2] === 1e7,
      `after 1006: the first delay, then growing (${sleeps.slice(0, 3).join(", ")} ms)`);
    await back;
  }
  await sub.close();
}

await dropAndCount(1001);
await dropAndCount(1006);
console.log(failures ? `${failures} failure(s)` : "all passed");
process.exit(failures ? 1 : 0);

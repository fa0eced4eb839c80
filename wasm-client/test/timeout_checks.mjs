// Timing checks of the wasm client's own timers, run in node (timeouts_test.mjs) and in Chromium
// (reconnect.html?checks=timeouts): heartbeats keep an idle connection past receiveTimeoutMs, a silent
// network is noticed within receiveTimeoutMs (plus 500 ms), a connect into it fails after timeoutMs, and
// rr.subscribe() notices the cut and reports its failed attempts just as fast. Each bound here is the
// check itself, so the tests that run these are labelled `timing` (ctest's calm phase); the reconnect
// checks (reconnect_checks.mjs) only wait for the same events.
//
// runTimeoutChecks(rr, {url, control: {cut, restore}, log}) → {passed: [names], failed: [{name, error}]}

const HEARTBEAT_MS = 300;
const RECEIVE_MS = 1200;
const CONNECT_MS = 1500;
const SLACK_MS = 500;  // timer granularity and one event-loop turn or two, on a calm machine

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function until(cond, what, timeoutMs = 30000) {
  const end = performance.now() + timeoutMs;
  while (!cond()) {
    if (performance.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(5);
  }
}

export async function runTimeoutChecks(rr, { url, control, log = console.log }) {
  const passed = [];
  const failed = [];
  const check = async (name, fn) => {
    try {
      const note = await fn();
      passed.push(name);
      log(`ok   ${name}${note ? `: ${note}` : ""}`);
    } catch (e) {
      failed.push({ name, error: String(e?.stack ?? e) });
      log(`FAIL ${name}: ${e?.message ?? e}`);
    }
  };
  const assert = (cond, what) => {
    if (!cond) throw new Error(what);
  };
  const ms = (x) => `${Math.round(x)} ms`;

  let c = null;
  let closed = null;  // {at, error}
  await check(`an idle connection outlives receiveTimeoutMs (${RECEIVE_MS} ms) three times over: heartbeats answered`, async () => {
    c = await rr.connect(url, { heartbeatPeriodMs: HEARTBEAT_MS, receiveTimeoutMs: RECEIVE_MS });
    c.$client.onClose((error) => (closed ??= { at: performance.now(), error }));
    await sleep(4 * RECEIVE_MS);  // the duration is the check: nothing sent by the test meanwhile
    assert(c.$client.state === "connected" && closed === null,
      `state ${c.$client.state} after ${4 * RECEIVE_MS} ms idle${closed ? `: closed with ${closed.error?.message}` : ""}`);
  });

  let cut = false;
  await check(`a silent network is noticed within receiveTimeoutMs + ${SLACK_MS} ms`, async () => {
    assert(c && c.$client.state === "connected", "no connection from the check before");
    const t0 = performance.now();
    await control.cut();
    cut = true;
    await until(() => closed !== null, "the connection closed after the cut", RECEIVE_MS + 30000);
    const after = closed.at - t0;
    assert(closed.error?.errorName === "RobotRaconteur.ConnectionError", `closed with ${closed.error?.errorName}: ${closed.error?.message}`);
    assert(after <= RECEIVE_MS + SLACK_MS, `closed ${ms(after)} after the cut`);
    return `closed ${ms(after)} after the cut`;
  });

  await check(`a connect into the silent network fails after timeoutMs (${CONNECT_MS} ms)`, async () => {
    if (!cut) {
      await control.cut();
      cut = true;
    }
    const t0 = performance.now();
    const err = await rr.connect(url, { timeoutMs: CONNECT_MS, heartbeatPeriodMs: HEARTBEAT_MS, receiveTimeoutMs: RECEIVE_MS })
      .then((x) => x.$client.close().then(() => null), (e) => e);
    const after = performance.now() - t0;
    assert(err?.errorName === "RobotRaconteur.ConnectionError" && /timed out/.test(err.message), `connect gave ${err?.errorName}: ${err?.message}`);
    assert(after >= CONNECT_MS - 20 && after <= CONNECT_MS + SLACK_MS, `failed after ${ms(after)}`);
    return `failed after ${ms(after)}`;
  });
  if (cut) await control.restore();

  await check("rr.subscribe(): the cut noticed and each attempt into it failing as fast, then connected again", async () => {
    const options = { backoff: { initialMs: 50, maxMs: 400, factor: 2, jitter: 0.25 }, heartbeatPeriodMs: HEARTBEAT_MS,
      receiveTimeoutMs: RECEIVE_MS, timeoutMs: CONNECT_MS };
    const sub = rr.subscribe(url, options);
    const seen = { disconnectAt: null, errors: [] };
    sub.onDisconnect(() => (seen.disconnectAt ??= performance.now()));
    sub.onError((e) => seen.errors.push({ at: performance.now(), e }));
    try {
      await sub.getDefaultClientWait(20000);
      const t0 = performance.now();
      await control.cut();
      await until(() => seen.disconnectAt !== null, "onDisconnect after the cut", RECEIVE_MS + 30000);
      const noticed = seen.disconnectAt - t0;
      assert(noticed <= RECEIVE_MS + SLACK_MS, `onDisconnect ${ms(noticed)} after the cut`);
      // the first attempt starts after one backoff (at most initialMs + 25 %) and times out after timeoutMs
      await until(() => seen.errors.length > 0, "a failed attempt during the cut", CONNECT_MS + 30000);
      const first = seen.errors[0];
      const attempt = first.at - seen.disconnectAt;
      assert(first.e?.errorName === "RobotRaconteur.ConnectionError", `attempt failed with ${first.e?.errorName}: ${first.e?.message}`);
      assert(attempt <= 50 * 1.25 + CONNECT_MS + SLACK_MS, `the first attempt failed ${ms(attempt)} after onDisconnect`);
      await control.restore();
      await until(() => sub.clients[0]?.connectCount === 2, "connected again after the network is back");
      return `onDisconnect ${ms(noticed)} after the cut, the first attempt failed ${ms(attempt)} after it`;
    } finally {
      await sub.close();
    }
  });
  if (c && c.$client.state !== "closed") await c.$client.close();
  return { passed, failed };
}

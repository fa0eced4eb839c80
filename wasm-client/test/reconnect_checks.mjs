// Reconnect checks of rr.subscribe(), run in node (reconnect_test.mjs) and in Chromium (reconnect.html):
// one subscription to the interop service (directly or through rr-gateway) with a wire, a pipe, an
// event handler and two callbacks; after each disruption `control` causes (device restarted, gateway
// restarted, network cut silently, connections dropped) every one of them must work again on the new
// connection, each handler firing exactly once per value.
//
// Every wait here is for an event, bounded only against a hang (tens of seconds): these checks run in
// ctest's crowded main phase. How fast a silent cut is noticed (receiveTimeoutMs), that heartbeats keep
// an idle connection and that a connect into a silent network times out are timing checks:
// timeout_checks.mjs, in tests labelled `timing`.
//
// runReconnectChecks(rr, {url, control, log, heap, reconnects}) → {passed: [names], failed: [{name, error}]}
//   control: {restartDevice?, restartGateway?, cut?, restore?, dropAll?} async functions (the runner's)
//   heap: () => bytes of live heap after a full GC (null: none; with control.dropAll that fails the memory check)

export const FAST = {
  // Quick reconnects for a test; the defaults (0.5 s .. 10 s) are for real networks.
  backoff: { initialMs: 50, maxMs: 400, factor: 2, jitter: 0.25 },
  // A stall of the page, node or the gateway under CI load must not look like a dead peer: a spurious
  // receive timeout is one reconnect too many (1.2 s, then 2.5 s, saw one in loaded CI runs).
  heartbeatPeriodMs: 500,
  receiveTimeoutMs: 6000,
  timeoutMs: 20000,  // connect and each request: a bound on a hang, not an expected duration
};

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function until(cond, what, timeoutMs = 30000) {
  const end = Date.now() + timeoutMs;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${typeof what === "function" ? what() : what}`);
    await sleep(10);
  }
}

export async function runReconnectChecks(rr, { url, control, log = console.log, heap = null, reconnects = 100 }) {
  const passed = [];
  const failed = [];
  const check = async (name, fn) => {
    const t0 = Date.now();
    try {
      const note = await fn();
      passed.push(name);
      log(`ok   ${name} (${Date.now() - t0} ms)${note ? `: ${note}` : ""}`);
    } catch (e) {
      failed.push({ name, error: String(e?.stack ?? e) });
      log(`FAIL ${name}: ${e?.message ?? e}`);
    }
  };
  const assert = (cond, what) => {
    if (!cond) throw new Error(what);
  };

  const sub = rr.subscribe(url, FAST);
  const seen = { connects: 0, disconnects: 0, errors: [], wire: 0, wireKeys: new Set(), wireDup: 0, events: [], packets: [], notifies: 0,
    wireOpens: 0, wireCloses: 0, pipeOpens: 0, pipeCloses: 0, attempts: 0 };
  sub.onConnecting(() => seen.attempts++);
  sub.onConnect(() => seen.connects++);
  sub.onDisconnect(() => seen.disconnects++);
  sub.onError((e) => seen.errors.push(e?.message));
  const wire = sub.subscribeWire("w_state");
  wire.onValueChanged((v, ts) => {
    seen.wire++;
    const key = `${v.id}/${v.label}/${ts.seconds}.${ts.nanoseconds}`;
    if (seen.wireKeys.has(key)) seen.wireDup++;
    seen.wireKeys.add(key);
  });
  const pipe = sub.subscribePipe("p_stream", "", 10);
  pipe.onPacketReceived((p) => seen.packets.push(p[0]));
  // the member connections' own events: one open per (re)connection of each, one close per loss
  wire.onConnect(() => seen.wireOpens++);
  wire.onDisconnect(() => seen.wireCloses++);
  pipe.onConnect(() => seen.pipeOpens++);
  pipe.onDisconnect(() => seen.pipeCloses++);
  sub.subscribeEvent("ev_values", (seq) => seen.events.push(seq));
  sub.setCallback("cb_compute", (x, label) => x * 2 + label.length);
  sub.setCallback("cb_notify", () => {
    seen.notifies++;
  });

  /** Everything opened on the subscription works (again), each handler firing once per push. */
  const works = async (what) => {
    const c = await sub.getDefaultClientWait(20000);
    await until(() => wire.activeWireConnectionCount === 1 && pipe.activePipeEndpointCount === 1, `${what}: wire and pipe restored`);
    const w0 = seen.wire;
    await until(() => seen.wire >= w0 + 2, `${what}: wire values`);
    assert(wire.inValueValid && typeof wire.inValue.id === "number", `${what}: inValue ${JSON.stringify(wire.tryGetInValue())}`);
    seen.events.length = 0;
    await c.fire_events(3);
    await until(() => seen.events.length >= 3, `${what}: 3 events`);
    seen.packets.length = 0;
    await c.send_stream(2);
    await until(() => seen.packets.length >= 2, `${what}: 2 pipe packets`);
    const n0 = seen.notifies;
    const r = await c.call_callbacks(1.5);
    assert(r === 1.5 * 2 + "\u03bb-label".length + 1, `${what}: call_callbacks gave ${r}`);
    // cb_notify is a request of the service's that call_callbacks waits for: counted by now
    assert(seen.notifies === n0 + 1, `${what}: cb_notify ran ${seen.notifies - n0} times`);
    // A fence instead of a pause: one more event and one more packet, sent after the ones above on the
    // same connection, arrive after any second copy of those; the lists are compared once they did.
    await c.fire_events(1);
    await until(() => seen.events.length >= 4, `${what}: the fence event`);
    await c.send_stream(1);
    await until(() => seen.packets.length >= 3, `${what}: the fence packet`);
    assert(JSON.stringify(seen.events.slice(0, 4)) === "[0,1,2,0]", `${what}: events ${JSON.stringify(seen.events)} (each once, then the fence)`);
    assert(JSON.stringify(seen.packets.slice(0, 3)) === "[0,1,0]", `${what}: packets ${JSON.stringify(seen.packets)} (each once, then the fence)`);
    assert(seen.wireDup === 0, `${what}: ${seen.wireDup} wire values delivered twice`);
    assert(sub.state === "connected" && sub.clients[0].state === "connected", `${what}: state ${sub.state}/${sub.clients[0].state}`);
  };
  const client = () => sub.clients[0];

  /**
   * The wire's and pipe's own onConnect fired once more than their onDisconnect (each open now), and
   * each closed and opened again at least `opens.wire` / `opens.pipe` times since `before`.
   */
  const memberEvents = async (what, before, opens) => {
    const moved = () => seen.wireOpens >= before.wireOpens + opens.wire && seen.pipeOpens >= before.pipeOpens + opens.pipe;
    await until(() => seen.wireOpens === seen.wireCloses + 1 && seen.pipeOpens === seen.pipeCloses + 1 && moved(),
      () => `${what}: member onConnect/onDisconnect (wire opens/closes ${seen.wireOpens}/${seen.wireCloses}, pipe ${seen.pipeOpens}/${seen.pipeCloses}, before ${JSON.stringify(before)})`);
    const counts = `wire ${seen.wireOpens}/${seen.wireCloses}, pipe ${seen.pipeOpens}/${seen.pipeCloses}`;
    assert(seen.wireCloses >= before.wireCloses + opens.wire && seen.pipeCloses >= before.pipeCloses + opens.pipe, `${what}: closes ${counts}`);
    return counts;
  };
  const memberCounts = () => ({ wireOpens: seen.wireOpens, wireCloses: seen.wireCloses, pipeOpens: seen.pipeOpens, pipeCloses: seen.pipeCloses });

  await check("first connection: wire, pipe, event, callbacks", async () => {
    await works("first");
    assert(client().connectCount === 1 && seen.connects === 1, `connectCount ${client().connectCount}, onConnect ${seen.connects}`);
    assert(seen.attempts === 1, `onConnecting fired ${seen.attempts} times for one connection`);
    await until(() => seen.wireOpens === 1 && seen.pipeOpens === 1, "the wire's and pipe's onConnect");
    assert(seen.wireCloses === 0 && seen.pipeCloses === 0, `closes before any drop: wire ${seen.wireCloses}, pipe ${seen.pipeCloses}`);
  });

  if (control.restartDevice) {
    await check("device restarted: everything resumes", async () => {
      const c0 = client().connectCount;
      const m0 = memberCounts();
      await control.restartDevice();
      await works("after device restart");
      // the pipe endpoint goes with the device; a wire connection through the gateway may stay open
      // (the gateway connects the device's wire again behind it): then it only has to be open now
      const members = await memberEvents("after device restart", m0, { wire: 0, pipe: 1 });
      return `connections ${c0} -> ${client().connectCount}, onDisconnect ${seen.disconnects}; member opens/closes ${members}`;
    });
  }

  if (control.restartGateway) {
    await check("gateway restarted: reconnects and everything resumes", async () => {
      const c0 = client().connectCount;
      const d0 = seen.disconnects;
      const m0 = memberCounts();
      await control.restartGateway();
      await works("after gateway restart");
      await memberEvents("after gateway restart", m0, { wire: 1, pipe: 1 });
      assert(client().connectCount === c0 + 1 && seen.disconnects === d0 + 1,
        `connectCount ${c0} -> ${client().connectCount}, onDisconnect +${seen.disconnects - d0} (want +1 each)`);
      assert(seen.attempts >= seen.connects, `onConnecting ${seen.attempts} times, onConnect ${seen.connects}: every connection had its attempt`);
    });
  }

  if (control.cut) {
    await check("network cut silently: noticed (receive timeout), getDefaultClient refuses, resumes after", async () => {
      const d0 = seen.disconnects;
      const c0 = client().connectCount;
      const t0 = performance.now();
      await control.cut();
      await until(() => seen.disconnects > d0, "onDisconnect after the cut", FAST.receiveTimeoutMs + 30000);
      const noticed = performance.now() - t0;  // logged; its bound is checked in timeout_checks.mjs (timing)
      assert(sub.state === "connecting" && sub.getConnectedClients().size === 0, `state during the cut: ${sub.state}`);
      let threw = null;
      try {
        sub.getDefaultClient();
      } catch (e) {
        threw = e;
      }
      assert(threw?.errorName === "RobotRaconteur.ConnectionError", "getDefaultClient during the cut");
      // A connect attempt in flight now hangs in the silent network; restore() ends it and the next succeeds.
      await control.restore();
      await works("after the cut");
      assert(client().connectCount === c0 + 1, `connectCount ${c0} -> ${client().connectCount}`);
      return `noticed after ${Math.round(noticed)} ms (receiveTimeoutMs ${FAST.receiveTimeoutMs})`;
    });
  }

  if (control.dropAll) {
    await check(`memory flat over ${reconnects} reconnects`, async () => {
      // the runner asked for it: without a heap figure it did not run, which is a failure, not a pass
      assert(heap, "no heap measurement here (node --expose-gc; Chromium --js-flags=--expose-gc --enable-precise-memory-info)");
      const reconnectOnce = async () => {
        const c0 = client().connectCount;
        await control.dropAll();
        await until(() => client().connectCount > c0 && wire.activeWireConnectionCount === 1 && pipe.activePipeEndpointCount === 1, "reconnect");
      };
      for (let i = 0; i < 20; i++) await reconnectOnce();  // warm-up: code optimized, caches and pools filled
      // Every connection's root proxy, weakly: once a connection is gone nothing may hold it.
      const refs = [];
      const offRef = sub.onConnect((cl, proxy) => refs.push(new WeakRef(proxy)));
      await sleep(100);
      const h0 = await heap();
      const t0 = performance.now();
      for (let i = 0; i < reconnects; i++) await reconnectOnce();
      const ms = performance.now() - t0;
      offRef();
      await sleep(Number(globalThis.process?.env?.SUBS_SLEEP ?? 100));
      // A closed connection may still be referenced by a timer of its own for a bounded time (a
      // request's or a receive timeout): that is not a leak. Measure again for up to 20 s until the
      // figures settle; a connection kept for good stays alive through all of it.
      let h1, aliveAt, waited = 0;
      for (;;) {
        h1 = await heap();
        await sleep(0);
        aliveAt = refs.flatMap((r, i) => (r.deref() !== undefined ? [i] : []));
        if ((aliveAt.length <= 1 && h1 - h0 < reconnects * 10e3) || waited >= 20000) break;
        await sleep(1000);
        waited += 1000;
      }
      const alive = aliveAt.length;
      await works(`after ${reconnects} reconnects`);
      const grew = h1 - h0;
      const note = `heap ${(h0 / 1e6).toFixed(2)} MB -> ${(h1 / 1e6).toFixed(2)} MB (${grew >= 0 ? "+" : ""}${(grew / 1e3).toFixed(0)} kB, ` +
        `${(grew / reconnects / 1e3).toFixed(1)} kB per reconnect); root proxies still alive: ${alive} of ${refs.length} [${aliveAt}]; ` +
        `${reconnects} reconnects in ${Math.round(ms)} ms${waited ? `; measured again after ${waited / 1000} s` : ""}`;
      // A kept connection (its proxies: the interop root alone has ~90 members) would be tens of kB each; what
      // grows here is V8's optimized code (heap snapshots: code, deopt data, feedback vectors), ~2 kB per reconnect.
      assert(alive <= 1, `connections kept after they closed: ${note}`);
      assert(grew < reconnects * 10e3, `heap grew: ${note}`);
      return note;
    });
  }

  await check("close(): no more reconnects, state closed", async () => {
    await sub.close();
    const c = client();
    assert(sub.state === "closed" && c.state === "closed", `state ${sub.state}/${c.state}`);
    const w0 = seen.wire;
    const n0 = c.connectCount;
    await sleep(500);
    assert(seen.wire === w0 && c.connectCount === n0, "values or connections after close()");
    let threw = null;
    try {
      sub.subscribeWire("w_state");
    } catch (e) {
      threw = e;
    }
    assert(threw?.errorName === "RobotRaconteur.InvalidOperation", "subscribeWire after close()");
  });
  return { passed, failed };
}

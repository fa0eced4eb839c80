// Reconnect checks of rr.subscribe(), run in node (reconnect_test.mjs) and in Chromium (reconnect.html):
// one subscription to the interop service (directly or through rr-gateway) with a wire, a pipe, an
// event handler and two callbacks; after each disruption `control` causes (device restarted, gateway
// restarted, network cut silently, connections dropped) every one of them must work again on the new
// connection, each handler firing exactly once per value.
//
// runReconnectChecks(rr, {url, control, log, heap, reconnects}) → {passed: [names], failed: [{name, error}]}
//   control: {restartDevice?, restartGateway?, cut?, restore?, dropAll?} async functions (the runner's)
//   heap: () => bytes of live heap after a full GC (null: no memory check)

export const FAST = {
  // Fast enough for a test; the defaults (0.5 s .. 10 s, 10 s / 15 s) are for real networks.
  backoff: { initialMs: 50, maxMs: 400, factor: 2, jitter: 0.25 },
  heartbeatPeriodMs: 300,
  receiveTimeoutMs: 2500,  // 8 heartbeats: 1.2 s saw a spurious timeout in a loaded CI run (Chromium stalled)
  timeoutMs: 3000,
};

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function until(cond, what, timeoutMs = 15000) {
  const end = Date.now() + timeoutMs;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
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
  const seen = { connects: 0, disconnects: 0, errors: [], wire: 0, wireKeys: new Set(), wireDup: 0, events: [], packets: [], notifies: 0 };
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
    await sleep(300);  // room for a duplicate to show up
    assert(JSON.stringify(seen.events) === "[0,1,2]", `${what}: events ${JSON.stringify(seen.events)} (each once)`);
    assert(JSON.stringify(seen.packets) === "[0,1]", `${what}: packets ${JSON.stringify(seen.packets)} (each once)`);
    assert(seen.notifies === n0 + 1, `${what}: cb_notify ran ${seen.notifies - n0} times`);
    assert(seen.wireDup === 0, `${what}: ${seen.wireDup} wire values delivered twice`);
    assert(sub.state === "connected" && sub.clients[0].state === "connected", `${what}: state ${sub.state}/${sub.clients[0].state}`);
  };
  const client = () => sub.clients[0];

  await check("first connection: wire, pipe, event, callbacks", async () => {
    await works("first");
    assert(client().connectCount === 1 && seen.connects === 1, `connectCount ${client().connectCount}, onConnect ${seen.connects}`);
  });

  if (control.restartDevice) {
    await check("device restarted: everything resumes", async () => {
      const c0 = client().connectCount;
      await control.restartDevice();
      await works("after device restart");
      return `connections ${c0} -> ${client().connectCount}, onDisconnect ${seen.disconnects}`;
    });
  }

  if (control.restartGateway) {
    await check("gateway restarted: reconnects and everything resumes", async () => {
      const c0 = client().connectCount;
      const d0 = seen.disconnects;
      await control.restartGateway();
      await works("after gateway restart");
      assert(client().connectCount === c0 + 1 && seen.disconnects === d0 + 1,
        `connectCount ${c0} -> ${client().connectCount}, onDisconnect +${seen.disconnects - d0} (want +1 each)`);
    });
  }

  if (control.cut) {
    await check(`network cut silently: noticed within receiveTimeoutMs (${FAST.receiveTimeoutMs} ms), resumes after`, async () => {
      const d0 = seen.disconnects;
      const c0 = client().connectCount;
      const t0 = performance.now();
      await control.cut();
      await until(() => seen.disconnects > d0, "onDisconnect after the cut", FAST.receiveTimeoutMs + 5000);
      const noticed = performance.now() - t0;
      assert(noticed <= FAST.receiveTimeoutMs + 500, `noticed after ${Math.round(noticed)} ms`);
      assert(sub.state === "connecting" && sub.getConnectedClients().size === 0, `state during the cut: ${sub.state}`);
      let threw = null;
      try {
        sub.getDefaultClient();
      } catch (e) {
        threw = e;
      }
      assert(threw?.errorName === "RobotRaconteur.ConnectionError", "getDefaultClient during the cut");
      await sleep(FAST.timeoutMs + 500);  // connect attempts into the silent network time out
      const failedAttempts = seen.errors.length;
      await control.restore();
      await works("after the cut");
      assert(client().connectCount === c0 + 1, `connectCount ${c0} -> ${client().connectCount}`);
      return `noticed after ${Math.round(noticed)} ms; ${failedAttempts} errors reported during the cut`;
    });
  }

  if (control.dropAll && heap) {
    await check(`memory flat over ${reconnects} reconnects`, async () => {
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

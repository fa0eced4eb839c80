// One wire subscription per object and wire, shared by the views that show it (src/views/shared_wire.js),
// on the client package's real ServiceSubscription (wasm-client/src/subscription.mjs) with a stand-in
// service whose wire refuses a second connection as an RR client does ("already connected").
import { test } from "node:test";
import assert from "node:assert/strict";
import { followWire, sharedUsers } from "../src/views/shared_wire.js";
import { ServiceSubscription } from "../../wasm-client/src/subscription.mjs";

/** A stand-in service with wire `state`: one connection at a time, values pushed with send(). */
function standIn() {
  const wire = { connects: 0, open: null, seconds: 0 };
  const client = { state: "connected", onClose() { return () => {}; }, async close() {} };
  const root = {
    $client: client, $type: "t.T", $members: [{ name: "state", kind: "wire", type: "int32" }],
    state: {
      async connect() {
        if (wire.open) throw new Error('RobotRaconteur.InvalidOperation: wire "state" already connected');
        wire.connects++;
        const conn = {
          changes: new Set(), closes: new Set(), value: undefined, ts: null, closed: false,
          get inValueValid() { return conn.value !== undefined; },
          get inValue() { if (conn.value === undefined) throw new Error("ValueNotSet"); return conn.value; },
          get inValueTime() { return conn.ts; },
          set outValue(v) { wire.out = v; },
          onChange(fn) { conn.changes.add(fn); return () => conn.changes.delete(fn); },
          onClose(fn) { conn.closes.add(fn); return () => conn.closes.delete(fn); },
          async close() { wire.end(null); },
        };
        if (wire.last !== undefined) { conn.value = wire.last.value; conn.ts = wire.last.ts; }
        wire.open = conn;
        return conn;
      },
    },
  };
  wire.send = (v) => {
    const ts = { seconds: ++wire.seconds, nanoseconds: 0 };
    wire.last = { value: v, ts };
    wire.open.value = v;
    wire.open.ts = ts;
    for (const fn of wire.open.changes) fn(v, ts);
  };
  wire.end = (err) => {
    const c = wire.open;
    if (!c || c.closed) return;
    c.closed = true;
    wire.open = null;
    for (const fn of c.closes) fn(err);
  };
  const sub = new ServiceSubscription("rr+ws://gw/?service=d", { backoff: { initialMs: 1, maxMs: 5 } }, async () => root);
  return { sub, wire };
}

/** Waits for `cond` (an event the code under test causes), bounded only against a hang. */
async function until(cond, what, timeoutMs = 20000) {
  const end = Date.now() + timeoutMs;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await new Promise((r) => setTimeout(r, 5));
  }
}

test("two views of one wire share one connection; it closes with the last of them", async () => {
  const { sub, wire } = standIn();
  const seen = { a: [], b: [], c: [] };
  const a = followWire(sub, "", "state", { onValue: (v) => seen.a.push(v) });
  const b = followWire(sub, "", "state", { onValue: (v) => seen.b.push(v) });
  await until(() => a.connected && b.connected, "both views connected");
  assert.equal(wire.connects, 1);
  assert.equal(sharedUsers(sub, "", "state"), 2);
  wire.send(1);
  await until(() => seen.a.length && seen.b.length, "the value in both views");
  assert.deepEqual([seen.a, seen.b], [[1], [1]]);
  // a third view, joining late, gets the newest value at once
  const c = followWire(sub, "", "state", { onValue: (v) => seen.c.push(v) });
  await until(() => seen.c.length === 1, "the late view's first value");
  assert.deepEqual(seen.c, [1]);
  assert.equal(wire.connects, 1);
  a.dispose();
  c.dispose();
  wire.send(2);
  await until(() => seen.b.length === 2, "the second value in b");
  assert.deepEqual([seen.a, seen.b], [[1], [1, 2]]);
  assert.ok(wire.open, "still open for b");
  b.dispose();
  await until(() => wire.open === null, "the connection closed with the last view");
  assert.equal(sharedUsers(sub, "", "state"), 0);
  // a new view connects again
  const d = followWire(sub, "", "state", { onValue: () => {} });
  await until(() => d.connected, "a new view connected");
  assert.equal(wire.connects, 2);
  d.dispose();
  await sub.close();
});

test("followWire: a panel and a card on the same wire both hear a close and follow the reconnect", async () => {
  const { sub, wire } = standIn();
  const panel = [], card = [], errors = [], cardErrors = [];
  const p = followWire(sub, "", "state", { onValue: (v) => panel.push(v), onError: (e) => errors.push(e?.message ?? null) });
  const c = followWire(sub, "", "state", { onValue: (v) => card.push(v), onError: (e) => cardErrors.push(e?.message ?? null) });
  await until(() => errors.length >= 1 && cardErrors.length >= 1, "both followers open");
  assert.equal(wire.connects, 1, "one connection for both");
  wire.send("x");
  await until(() => panel.length && card.length, "the value in both views");
  assert.deepEqual([panel, card], [["x"], ["x"]]);
  wire.end(new Error("device gone"));
  await until(() => errors.length >= 2 && cardErrors.length >= 2, "both followers told of the close");
  assert.deepEqual(errors.slice(0, 2), [null, "device gone"]);
  // each follower says it is open again with onError(null): wait for both, then count the connections
  await until(() => errors.length >= 3 && cardErrors.length >= 3, "both followers open again");
  assert.deepEqual([errors, cardErrors], [[null, "device gone", null], [null, "device gone", null]]);
  assert.equal(wire.connects, 2, "reconnected once, for both");
  // the value the new connection starts with is the one already shown: not shown twice
  wire.send("y");
  await until(() => panel.length >= 2 && card.length >= 2, "the next value in both views");
  assert.deepEqual([panel, card], [["x", "y"], ["x", "y"]]);
  // an out value goes on the open connection
  p.setOutValue(5);
  assert.equal(wire.out, 5);
  p.dispose();
  c.dispose();
  await until(() => wire.open === null, "closed with the last view");
  assert.throws(() => p.setOutValue(6), /not connected/);
  await sub.close();
});

test("a view that leaves before the connection is made does not keep it open", async () => {
  const { sub, wire } = standIn();
  const f = followWire(sub, "", "state", { onValue: () => {} });
  f.dispose();
  // the subscription connects the service (an event), then nothing asks for the wire
  await until(() => sub.clients[0]?.state === "connected", "the service connected");
  await new Promise((r) => setTimeout(r, 20));
  assert.equal(wire.open, null);
  assert.equal(wire.connects, 0);
  await sub.close();
});

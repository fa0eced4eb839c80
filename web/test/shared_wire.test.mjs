// One wire connection per object and wire, shared by the views that show it (src/views/shared_wire.js),
// against a stand-in wire that refuses a second connection as an RR client does ("already connected").
import { test } from "node:test";
import assert from "node:assert/strict";
import { connectShared, followWire, sharedUsers } from "../src/views/shared_wire.js";

/** A stand-in object with wire `state`: one connection at a time, values pushed with send(). */
function standIn() {
  const wire = { connects: 0, open: null };
  const obj = {
    state: {
      async connect() {
        if (wire.open) throw new Error('RobotRaconteur.InvalidOperation: wire "state" already connected');
        wire.connects++;
        const conn = {
          changes: new Set(), closes: new Set(), value: undefined, closed: false,
          get inValue() { if (conn.value === undefined) throw new Error("ValueNotSet"); return conn.value; },
          onChange(fn) { conn.changes.add(fn); return () => conn.changes.delete(fn); },
          onClose(fn) { conn.closes.add(fn); return () => conn.closes.delete(fn); },
          async close() { wire.end(null); },
        };
        wire.open = conn;
        return conn;
      },
    },
  };
  wire.send = (v) => { wire.open.value = v; for (const fn of wire.open.changes) fn(v); };
  wire.end = (err) => {
    const c = wire.open;
    if (!c || c.closed) return;
    c.closed = true;
    wire.open = null;
    for (const fn of c.closes) fn(err);
  };
  return { obj, wire };
}

const tick = () => new Promise((r) => setTimeout(r, 0));
/** Waits for `cond` (an event the code under test causes), bounded only against a hang. */
async function until(cond, what, timeoutMs = 20000) {
  const end = Date.now() + timeoutMs;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await new Promise((r) => setTimeout(r, 5));
  }
}

test("two views of one wire share one connection; it closes with the last of them", async () => {
  const { obj, wire } = standIn();
  const [a, b] = await Promise.all([connectShared(obj, "state"), connectShared(obj, "state")]);
  assert.equal(wire.connects, 1);
  assert.equal(sharedUsers(obj, "state"), 2);
  const seen = { a: [], b: [] };
  a.onChange((v) => seen.a.push(v));
  b.onChange((v) => seen.b.push(v));
  wire.send(1);
  assert.deepEqual(seen, { a: [1], b: [1] });
  // a third view, joining late, reads the newest value
  const c = await connectShared(obj, "state");
  assert.equal(c.inValue, 1);
  assert.equal(wire.connects, 1);
  await a.close();
  await c.close();
  wire.send(2);
  assert.deepEqual(seen, { a: [1], b: [1, 2] });
  assert.ok(wire.open, "still open for b");
  await b.close();
  assert.equal(wire.open, null, "closed with the last view");
  // a new view connects again
  const d = await connectShared(obj, "state");
  assert.equal(wire.connects, 2);
  await d.close();
});

test("the far side closing the wire tells every view; the next one reconnects", async () => {
  const { obj, wire } = standIn();
  const a = await connectShared(obj, "state");
  const b = await connectShared(obj, "state");
  const closed = [];
  a.onClose((e) => closed.push(["a", e?.message]));
  b.onClose((e) => closed.push(["b", e?.message]));
  wire.end(new Error("gone"));
  assert.deepEqual(closed, [["a", "gone"], ["b", "gone"]]);
  assert.equal(sharedUsers(obj, "state"), 0);
  const c = await connectShared(obj, "state");
  assert.equal(wire.connects, 2);
  await c.close();
});

test("followWire: a panel and a card on the same wire both follow it and reconnect after a close", async () => {
  const { obj, wire } = standIn();
  const panel = [], card = [], errors = [], cardErrors = [];
  const p = followWire(obj, "state", { onValue: (v) => panel.push(v), onError: (e) => errors.push(e?.message ?? null), reopenMs: 10 });
  const c = followWire(obj, "state", { onValue: (v) => card.push(v), onError: (e) => cardErrors.push(e?.message ?? null), reopenMs: 10 });
  await tick();
  await tick();
  assert.equal(wire.connects, 1, "one connection for both");
  wire.send("x");
  assert.deepEqual([panel, card], [["x"], ["x"]]);
  wire.end(new Error("device gone"));
  assert.deepEqual(errors, [null, "device gone"]);
  // each follower says it is open again with onError(null): wait for both, then count the connections
  await until(() => errors.length >= 3 && cardErrors.length >= 3, "both followers open again");
  assert.deepEqual([errors, cardErrors], [[null, "device gone", null], [null, "device gone", null]]);
  assert.equal(wire.connects, 2, "reconnected once, for both");
  wire.send("y");
  assert.deepEqual([panel, card], [["x", "y"], ["x", "y"]]);
  p.dispose();
  c.dispose();
  assert.equal(wire.open, null);
});

test("a view that leaves before the connection is made does not keep it open", async () => {
  const { obj, wire } = standIn();
  const f = followWire(obj, "state", { onValue: () => {} });
  f.dispose();
  await tick();
  await tick();
  assert.equal(wire.open, null);
});

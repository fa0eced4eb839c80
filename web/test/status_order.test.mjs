// The replay timeline's rule for which status to show (src/status_order.js): a poll that
// overlapped a user's change never undoes it, and a slow reply never replaces a newer one.
import { test } from "node:test";
import assert from "node:assert/strict";
import { StatusOrder } from "../src/status_order.js";

test("a poll issued before a change and answered after it is dropped (the loop box stays unticked)", () => {
  const o = new StatusOrder();
  const poll = o.beginPoll();
  const change = o.beginChange();
  assert.equal(o.accept(change), true, "the change's reply shows");
  o.endChange();
  assert.equal(o.accept(poll), false, "the older poll does not undo it");
});

test("a poll answered while a change is in flight is dropped, even if issued first", () => {
  const o = new StatusOrder();
  const poll = o.beginPoll();
  const change = o.beginChange();
  assert.equal(o.accept(poll), false);
  assert.equal(o.accept(change), true);
  o.endChange();
});

test("no poll starts while a change is in flight; after it settles polls show again", () => {
  const o = new StatusOrder();
  const change = o.beginChange();
  assert.equal(o.beginPoll(), null);
  o.endChange();
  assert.equal(o.accept(change), true, "a change's reply taken after endChange still shows");
  const poll = o.beginPoll();
  assert.notEqual(poll, null);
  assert.equal(o.accept(poll), true);
});

test("of two changes only the later one's reply shows, whichever comes back first", () => {
  const o = new StatusOrder();
  const a = o.beginChange();
  const b = o.beginChange();
  assert.equal(o.accept(b), true);
  o.endChange();
  assert.equal(o.accept(a), false, "the first change's late reply is older");
  o.endChange();
  const c = o.beginChange(), d = o.beginChange();
  assert.equal(o.accept(c), true, "in order, each reply shows");
  assert.equal(o.accept(d), true);
});

test("polls: a slow reply never replaces a newer poll's", () => {
  const o = new StatusOrder();
  const p1 = o.beginPoll();
  const p2 = o.beginPoll();
  assert.equal(o.accept(p2), true);
  assert.equal(o.accept(p1), false);
  assert.equal(o.accept(null), false, "no ticket, nothing shown");
});

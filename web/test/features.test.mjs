// The page's one question about the gateway's optional parts (src/features.js, GET api/features in
// docs/json-api.md): answered features, an old gateway without the route, a gateway that is down.
import { test } from "node:test";
import assert from "node:assert/strict";
import { loadFeatures, parseFeatures, NO_FEATURES } from "../src/features.js";

const answer = (status, body) => ({ ok: status >= 200 && status < 300, status, json: async () => body });

test("only `true` turns a feature on", () => {
  assert.deepEqual(parseFeatures({ discovery: true, auth: false }), { discovery: true, auth: false });
  assert.deepEqual(parseFeatures({ discovery: "yes", auth: 1 }), NO_FEATURES);
  assert.deepEqual(parseFeatures(null), NO_FEATURES);
});

test("one request when the gateway answers", async () => {
  const asked = [];
  const f = await loadFeatures({ fetchFn: async (url) => { asked.push(url); return answer(200, { discovery: true, auth: true }); } });
  assert.deepEqual(f, { discovery: true, auth: true });
  assert.deepEqual(asked, ["api/features"]);
});

test("an error status (a gateway without the route) means no optional part, asked once", async () => {
  let n = 0;
  const f = await loadFeatures({ fetchFn: async () => { n++; return answer(404, { error: {} }); } });
  assert.deepEqual(f, NO_FEATURES);
  assert.equal(n, 1);
});

test("a network failure is asked again until the gateway answers", async () => {
  let n = 0;
  const waits = [];
  const f = await loadFeatures({
    retryMs: 5,
    sleep: async (ms) => { waits.push(ms); },
    fetchFn: async () => { if (++n < 3) throw new TypeError("Failed to fetch"); return answer(200, { discovery: false, auth: true }); },
  });
  assert.deepEqual(f, { discovery: false, auth: true });
  assert.equal(n, 3);
  assert.deepEqual(waits, [5, 5]);
});

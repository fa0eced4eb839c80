// The discovered view's model (src/discovered_list.js) over GET api/discovered answers as the gateway
// sends them (docs/json-api.md "Discovery"), and over malformed ones.
import { test } from "node:test";
import assert from "node:assert/strict";
import { discoveredModel, addRequest } from "../src/discovered_list.js";

const ID1 = "11111111-2222-4333-8444-555555555555";
const ID2 = "aaaaaaaa-2222-4333-8444-555555555555";

test("nodes sorted by NodeName, services by name; a service without a device can be added", () => {
  const m = discoveredModel({
    nodes: [
      { nodeid: ID2, nodename: "zeta", source: "local", urls: [`rr+local:///?nodeid=${ID2}&service=RobotRaconteurServiceIndex`],
        nonce: "x", error: null,
        services: [{ name: "b", root_object_type: "a.B", device: "b" }, { name: "a", root_object_type: "a.A", device: null }] },
      { nodeid: ID1, nodename: "alpha", source: "usb", urls: [`rr+usb:///?nodeid=${ID1}&service=RobotRaconteurServiceIndex`],
        services: null, error: null },
    ],
    usb_problems: [{ device: "1209:0001", path: "/dev/bus/usb/001/004", error: "no permission: install the udev rule" }],
  });
  assert.deepEqual(m.nodes.map((n) => n.nodename), ["alpha", "zeta"]);
  assert.equal(m.nodes[0].known, false);
  assert.equal(m.nodes[0].source, "usb");
  assert.deepEqual(m.nodes[1].services, [
    { name: "a", type: "a.A", device: null, canAdd: true },
    { name: "b", type: "a.B", device: "b", canAdd: false },
  ]);
  assert.equal(m.nodes[1].urls[0], `rr+local:///?nodeid=${ID2}&service=RobotRaconteurServiceIndex`);
  assert.deepEqual(m.problems, [{ device: "1209:0001", path: "/dev/bus/usb/001/004", error: "no permission: install the udev rule" }]);
});

test("nodes without a NodeName come after named ones; interrogation errors are kept", () => {
  const m = discoveredModel({ nodes: [{ nodeid: ID1, nodename: "", services: null, error: "ConnectionError: refused" },
                                      { nodeid: ID2, nodename: "n", services: [] }] });
  assert.deepEqual(m.nodes.map((n) => n.nodeid), [ID2, ID1]);
  assert.equal(m.nodes[1].error, "ConnectionError: refused");
  assert.equal(m.nodes[0].known, true);
});

test("malformed answers give an empty or partial model, never a throw", () => {
  for (const bad of [null, undefined, 42, "x", {}, { nodes: "x" }, { nodes: [null, 1, { nodename: "no id" }] }]) {
    assert.deepEqual(discoveredModel(bad), { nodes: [], problems: [] });
  }
  const m = discoveredModel({ nodes: [{ nodeid: ID1, services: [null, { name: 3 }, { name: "ok" }], urls: "x" }], usb_problems: [{}, null] });
  assert.equal(m.nodes.length, 1);
  assert.deepEqual(m.nodes[0].services.map((s) => s.name), ["ok"]);
  assert.deepEqual(m.nodes[0].urls, []);
  assert.deepEqual(m.problems, []);
});

test("the add request names the node and the service", () => {
  assert.deepEqual(addRequest(ID1, "reynard"), { nodeid: ID1, service: "reynard" });
});

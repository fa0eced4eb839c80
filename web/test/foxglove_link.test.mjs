// The device page's Foxglove link (src/foxglove_link.js): the gateway's Foxglove WebSocket URL for the
// page's origin and folder (ws/wss by the page's scheme, a dashboard under a prefix keeps it), and
// Foxglove's web app link with that URL as its `ds.url`.
import { test } from "node:test";
import assert from "node:assert/strict";
import { foxgloveUrl, foxgloveAppLink } from "../src/foxglove_link.js";

test("the Foxglove WebSocket URL follows the page", () => {
  assert.equal(foxgloveUrl({ protocol: "http:", host: "127.0.0.1:8080", pathname: "/" }), "ws://127.0.0.1:8080/foxglove");
  assert.equal(foxgloveUrl({ protocol: "https:", host: "lab.example.org", pathname: "/rr/index.html" }), "wss://lab.example.org/rr/foxglove");
});

test("Foxglove's app link carries the URL as ds.url", () => {
  const link = new URL(foxgloveAppLink("ws://127.0.0.1:8080/foxglove"));
  assert.equal(link.searchParams.get("ds"), "foxglove-websocket");
  assert.equal(link.searchParams.get("ds.url"), "ws://127.0.0.1:8080/foxglove");
});

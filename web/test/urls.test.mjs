// The dashboard's URLs are relative to the page, so it works under a reverse proxy's path prefix
// (docs/deployment.md, "nginx under a path prefix"): the RR session URL keeps the page's folder.
import { test } from "node:test";
import assert from "node:assert/strict";
import { deviceUrl } from "../src/device_session.js";

const at = (href) => {
  const u = new URL(href);
  return { protocol: u.protocol, host: u.host, pathname: u.pathname };
};

test("deviceUrl: at the root, rr+ws to the page's host", () => {
  assert.equal(deviceUrl("create", at("http://127.0.0.1:8080/#/create")), "rr+ws://127.0.0.1:8080/?service=create");
  assert.equal(deviceUrl("create", at("http://gw:8080/index.html")), "rr+ws://gw:8080/?service=create");
});

test("deviceUrl: under a prefix, the page's folder; https gives rr+wss", () => {
  assert.equal(deviceUrl("create", at("https://lab.example.org/rr/#/create")), "rr+wss://lab.example.org/rr/?service=create");
  assert.equal(deviceUrl("webcam", at("https://lab.example.org:8443/a/b/index.html?x=1")),
    "rr+wss://lab.example.org:8443/a/b/?service=webcam");
});

test("deviceUrl: device names are encoded as a query value", () => {
  assert.equal(deviceUrl("a b&c", at("http://h/rr/")), "rr+ws://h/rr/?service=a%20b%26c");
});

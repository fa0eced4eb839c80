// The device session (src/device_session.js) on the client package's subscription (the real
// ServiceSubscription of wasm-client/src/subscription.mjs) with a stand-in for the package's connect: a
// device that refuses the login (AuthenticationError) makes the session wait for login() instead of
// retrying; other failures are retried; logout() closes the session and waits again.
import { test } from "node:test";
import assert from "node:assert/strict";
import { DeviceSession, isAuthenticationError } from "../src/device_session.js";
import { ServiceSubscription } from "../../wasm-client/src/subscription.mjs";

class FakeError extends Error {
  constructor(errorName, message) {
    super(message);
    this.errorName = errorName;
  }
}

/** A device with one user: connect() as the client package does it, recording every attempt. */
function fakeDevice({ users = { alice: "alice-pw" }, failFirst = 0 } = {}) {
  const dev = { attempts: [], open: new Set() };
  dev.connect = async (url, options) => {
    dev.attempts.push({ username: options.username, password: options.password });
    if (failFirst > 0) {
      failFirst--;
      throw new FakeError("RobotRaconteur.ConnectionError", "connection refused");
    }
    if (users) {
      if (!options.username) throw new FakeError("RobotRaconteur.AuthenticationError", "Username not provided");
      if (users[options.username] !== options.password) throw new FakeError("RobotRaconteur.AuthenticationError", "Invalid username or password");
    }
    const listeners = [];
    const client = {
      state: "connected",
      async close() {
        if (!dev.open.delete(client)) return;
        client.state = "closed";
        for (const fn of listeners) fn(null);
      },
      onClose(fn) { listeners.push(fn); },
    };
    dev.open.add(client);
    return { $client: client, $type: "t.T" };
  };
  // the client package's subscribe(url, options), connecting with the stand-in
  dev.subscribe = (url, options) => new ServiceSubscription(url, options, dev.connect);
  return dev;
}

/** Resolves with the next "state" event whose state is `want`. */
function next(session, want) {
  return new Promise((resolve) => {
    const on = (ev) => {
      if (ev.detail.state !== want) return;
      session.removeEventListener("state", on);
      resolve(ev.detail);
    };
    session.addEventListener("state", on);
  });
}

test("isAuthenticationError: only the device's refusal of a login", () => {
  assert.equal(isAuthenticationError(new FakeError("RobotRaconteur.AuthenticationError", "x")), true);
  assert.equal(isAuthenticationError(new FakeError("RobotRaconteur.ConnectionError", "x")), false);
  assert.equal(isAuthenticationError(new Error("x")), false);
  assert.equal(isAuthenticationError(null), false);
});

test("a device without logins connects as before, with no credentials", async () => {
  const dev = fakeDevice({ users: null });
  const s = new DeviceSession("rr+ws://gw/?service=d", { subscribe: dev.subscribe });
  const connected = next(s, "connected");
  s.start();
  await connected;
  assert.deepEqual(dev.attempts, [{ username: undefined, password: undefined }]);
  s.stop();
  await s.loop;
});

test("refused login: waits for login() without retrying; a wrong password refuses again; the right one connects", async () => {
  const dev = fakeDevice();
  const s = new DeviceSession("rr+ws://gw/?service=d", { subscribe: dev.subscribe });
  let login = next(s, "login");
  s.start();
  assert.match((await login).error.message, /Username not provided/);
  await new Promise((r) => setTimeout(r, 1200)); // longer than two backoffs: no retry may happen
  assert.equal(dev.attempts.length, 1);
  s.retryNow(); // the gateway reporting the device back does not end the wait either
  await new Promise((r) => setTimeout(r, 50));
  assert.equal(dev.attempts.length, 1);

  login = next(s, "login");
  s.login("alice", "wrong");
  assert.match((await login).error.message, /Invalid username or password/);
  assert.equal(s.username, "alice");

  const connected = next(s, "connected");
  s.login("alice", "alice-pw");
  await connected;
  assert.deepEqual(dev.attempts.at(-1), { username: "alice", password: "alice-pw" });
  assert.equal(dev.open.size, 1);

  login = next(s, "login");
  const attempts = dev.attempts.length;
  s.logout();
  assert.equal((await login).error, null);
  assert.equal(dev.open.size, 0, "logout closes the session");
  assert.equal(dev.attempts.length, attempts, "logout does not connect again without credentials");
  assert.equal(s.username, null);
  s.stop();
  await s.loop;
});

test("other connect errors are retried with the credentials given", async () => {
  const dev = fakeDevice({ failFirst: 1 });
  const s = new DeviceSession("rr+ws://gw/?service=d", { subscribe: dev.subscribe, credentials: { username: "alice", password: "alice-pw" } });
  const closed = next(s, "closed");
  const connected = next(s, "connected");
  s.start();
  assert.match((await closed).error.message, /connection refused/);
  await connected;
  assert.deepEqual(dev.attempts, [{ username: "alice", password: "alice-pw" }, { username: "alice", password: "alice-pw" }]);
  s.stop();
  await s.loop;
  assert.equal(dev.open.size, 0);
});

test("stop() ends a wait for a login", async () => {
  const dev = fakeDevice();
  const s = new DeviceSession("rr+ws://gw/?service=d", { subscribe: dev.subscribe });
  const login = next(s, "login");
  s.start();
  await login;
  const stopped = next(s, "stopped");
  s.stop();
  await stopped;
  await s.loop;
});

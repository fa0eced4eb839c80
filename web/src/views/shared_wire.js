// One wire subscription per wire per object, shared by every view of the page that shows it. A Robot
// Raconteur client may hold a single connection to a wire member of an object (a second connect is
// refused with "already connected"), while the dashboard shows some wires twice: a panel (the robot
// panel's robot_state, the camera panel's camera_state, the 3D view) and the generic wire card below it.
//
//   const follow = followWire(subscription, "", "robot_state", { onValue, onError });
//   follow.dispose();   // this view is done; the wire's subscription closes when the last view is done
//
// The wire's connection is the device session's subscription's (wasm-client subscription.mjs
// `subscribeWire`): it connects the wire, connects it again with the package's backoff when the device
// or gateway closes it, and keeps the newest value. This file only counts the views.

const bySubscription = new WeakMap();  // subscription -> Map(servicePath + NUL + wire name -> entry)

const keyOf = (servicePath, name) => `${servicePath}\u0000${name}`;

/** Views sharing the subscription to wire `name` of the object at `servicePath` now (for tests and tools). */
export function sharedUsers(subscription, servicePath, name) {
  return bySubscription.get(subscription)?.get(keyOf(servicePath, name))?.users.size ?? 0;
}

function entryFor(subscription, servicePath, name) {
  let wires = bySubscription.get(subscription);
  if (!wires) bySubscription.set(subscription, (wires = new Map()));
  const key = keyOf(servicePath, name);
  let entry = wires.get(key);
  if (entry) return entry;
  const wire = subscription.subscribeWire(name, servicePath);
  entry = { wire, users: new Set() };
  const each = (fn) => { for (const u of [...entry.users]) fn(u); };
  wire.onValueChanged((v) => each((u) => u.onValue(v)));
  wire.onConnect(() => each((u) => u.onError(null)));
  wire.onDisconnect((c, err) => each((u) => u.onError(err ?? new Error(`wire ${name} closed`))));
  wire.onError((err) => each((u) => u.onError(err)));
  entry.release = (user) => {
    entry.users.delete(user);
    if (entry.users.size) return;
    if (wires.get(key) === entry) wires.delete(key);
    wire.close().catch(() => {});
  };
  wires.set(key, entry);
  return entry;
}

/**
 * Follows wire `name` of the object at `servicePath` (objref path below the root, "" for the root) of
 * the device session's `subscription` for as long as the view lives: onValue(value) for the newest
 * InValue (the one already there first), onError(error|null) when connecting fails or the connection
 * closes (null once it is open again; the subscription reconnects by itself). Returns
 * { dispose(), connected (a wire connection is open now), setOutValue(v) (sends on it; throws when none is) }.
 */
export function followWire(subscription, servicePath, name, { onValue, onError = () => {} }) {
  let entry;
  try {
    entry = entryFor(subscription, servicePath, name);
  } catch (e) {
    // the subscription closed already (the session is going): nothing to follow
    queueMicrotask(() => onError(e));
    return { dispose() {}, connected: false, setOutValue() { throw e; } };
  }
  const user = { onValue, onError };
  entry.users.add(user);
  let disposed = false;
  // what a view joining late has at once: the connection's state and the newest value
  queueMicrotask(() => {
    if (disposed) return;
    if (entry.wire.activeWireConnectionCount) onError(null);
    const latest = entry.wire.tryGetInValue();
    if (latest) onValue(latest.value);
  });
  return {
    get connected() { return !disposed && entry.wire.activeWireConnectionCount > 0; },
    setOutValue(v) {
      if (!this.connected) throw new Error(`wire ${name} is not connected`);
      entry.wire.setOutValueAll(v);
    },
    dispose() {
      if (disposed) return;
      disposed = true;
      entry.release(user);
    },
  };
}

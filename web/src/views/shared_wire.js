// One connection per wire per object, shared by every view of the page that shows it. A Robot
// Raconteur client may hold a single connection to a wire member of an object (a second connect is
// refused with "already connected"), while the dashboard shows some wires twice: a panel (the robot
// panel's robot_state, the camera panel's camera_state) and the generic wire card below it.
//
//   const use = await connectShared(obj, "robot_state");
//   use.onChange((value) => ...); use.onClose((err) => ...);
//   use.close();   // this view is done; the connection closes when the last view is done
//
// The connection is made by the first user and closed when the last user closes; when the device or
// gateway closes it, every user hears it (onClose) and the next connectShared makes a new one.

const byObject = new WeakMap();  // object proxy -> Map(member name -> entry)

/** Users sharing a wire connection of `obj` now (for tests and tools). */
export function sharedUsers(obj, name) {
  return byObject.get(obj)?.get(name)?.users.size ?? 0;
}

/**
 * Resolves with this caller's use of the connection to wire `name` of object proxy `obj`:
 * { onChange(fn) → remove, onClose(fn) → remove, inValue (throws when none yet), outValue (set),
 *   close() }. Rejects as the wire's connect() does.
 */
export function connectShared(obj, name) {
  let wires = byObject.get(obj);
  if (!wires) byObject.set(obj, (wires = new Map()));
  let entry = wires.get(name);
  if (!entry) {
    entry = { users: new Set(), conn: null, promise: null };
    entry.promise = Promise.resolve().then(() => obj[name].connect()).then((conn) => {
      entry.conn = conn;
      conn.onChange((v, ts) => { for (const u of entry.users) u.changed(v, ts); });
      conn.onClose((err) => {
        if (wires.get(name) === entry) wires.delete(name);
        for (const u of [...entry.users]) u.closed(err);
        entry.users.clear();
      });
      if (!entry.users.size) finish(entry, wires, name);  // every user left while it connected
      return conn;
    }, (e) => {
      if (wires.get(name) === entry) wires.delete(name);
      throw e;
    });
    wires.set(name, entry);
  }
  const use = new SharedUse(entry, () => {
    entry.users.delete(use);
    if (!entry.users.size && entry.conn) finish(entry, wires, name);
  });
  entry.users.add(use);
  return entry.promise.then(() => use, (e) => { entry.users.delete(use); throw e; });
}

function finish(entry, wires, name) {
  if (wires.get(name) === entry) wires.delete(name);
  entry.conn?.close().catch(() => {});
}

class SharedUse {
  constructor(entry, release) {
    this.entry = entry;
    this.release = release;
    this.changeFns = new Set();
    this.closeFns = new Set();
    this.done = false;
  }

  changed(v, ts) { for (const fn of this.changeFns) fn(v, ts); }

  closed(err) {
    if (this.done) return;
    this.done = true;
    for (const fn of this.closeFns) fn(err);
  }

  onChange(fn) { this.changeFns.add(fn); return () => this.changeFns.delete(fn); }

  onClose(fn) { this.closeFns.add(fn); return () => this.closeFns.delete(fn); }

  /** The newest InValue (throws as the connection does when none arrived yet). */
  get inValue() { return this.entry.conn.inValue; }

  set outValue(v) { this.entry.conn.outValue = v; }

  /** This view is done with the wire; resolves at once (the last user's close closes the connection). */
  close() {
    if (!this.done) {
      this.done = true;
      this.changeFns.clear();
      this.closeFns.clear();
      this.release();
    }
    return Promise.resolve();
  }
}

/**
 * Follows wire `name` of `obj` on a shared connection for as long as the view lives: onValue(value)
 * for the newest InValue (the one already there first), onError(error|null) when connecting fails or
 * the connection closes (null once connected again); reconnects `reopenMs` after a close.
 * Returns { dispose() }.
 */
export function followWire(obj, name, { onValue, onError = () => {}, reopenMs = 2000 }) {
  let use = null, disposed = false, timer = 0;
  const again = (err) => {
    use = null;
    if (disposed) return;
    onError(err ?? new Error(`wire ${name} closed`));
    timer = setTimeout(open, reopenMs);
  };
  async function open() {
    try {
      const u = await connectShared(obj, name);
      if (disposed) { u.close(); return; }
      use = u;
      onError(null);
      u.onChange((v) => onValue(v));
      u.onClose(again);
      let v;
      try { v = u.inValue; } catch { /* none yet: the next change brings it */ }
      if (v !== undefined) onValue(v);
    } catch (e) {
      again(e);
    }
  }
  open();
  return {
    dispose() {
      disposed = true;
      clearTimeout(timer);
      use?.close();
    },
  };
}

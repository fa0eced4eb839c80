// The locks a gateway reports for a device (GET api/devices: "locks": [{path, user, kind}]) as text.

/** "monitor lock on robot by alice; user lock on robot.tool by bob", or "" without locks. */
export function locksText(locks) {
  if (!Array.isArray(locks) || !locks.length) return "";
  return locks.map((l) => `${l?.kind ?? "?"} lock on ${l?.path || "(root)"}${l?.user ? ` by ${l.user}` : ""}`).join("; ");
}

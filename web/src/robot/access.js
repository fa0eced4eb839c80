// Who may move the robot: the gateway tells the page which members of a device its user may read,
// write or call (GET api/devices/<device>/access), and the panel shows a control only when the
// user may use its member. This only hides controls: the gateway still checks every request, and a
// refused call is shown and ends the jog.
//
// Answer: 200 { device, auth: bool, user, members: { "<member>": ["read", "write", "call"] }, lock: bool },
// or { auth: false, members: null, lock: null } when the gateway checks nothing.

/** The relative URL of the access endpoint; `deviceUser`: the device's own login (auth: passthrough). */
export function accessUrl(device, deviceUser = null) {
  const q = deviceUser ? `?device_user=${encodeURIComponent(deviceUser)}` : "";
  return `api/devices/${encodeURIComponent(device)}/access${q}`;
}

/**
 * Reads the access of this page's user to `device`: { members: null } (everything allowed) or
 * { members: {name: [ops]} }, plus user. A gateway without the endpoint (404) checks by its
 * own rules only: treated as members null (its refusals still stop a jog). Other failures throw
 * Error("access to <device>: ...") and the panel then shows no moving control.
 */
export async function fetchAccess(device, deviceUser = null, fetchImpl = globalThis.fetch) {
  const r = await fetchImpl(accessUrl(device, deviceUser), { headers: { Accept: "application/json" }, cache: "no-store" });
  if (r.status === 404) return { auth: false, user: null, members: null, unknown: true };
  if (!r.ok) throw new Error(`access to ${device}: HTTP ${r.status}`);
  const body = await r.json();
  if (!body || typeof body !== "object" || (body.members !== null && typeof body.members !== "object")) {
    throw new Error(`access to ${device}: not an access answer`);
  }
  return body;
}

/**
 * True when `access` lets the user take the device's locks (the roles' `lock` on its root object): the
 * panel offers "take the device lock" only then. A gateway that checks nothing, or answers without
 * `lock` (older gateways), leaves it to the gateway's own refusal.
 */
export function mayLock(access) {
  if (!access) return false;
  if (access.members === null || access.lock === undefined || access.lock === null) return true;
  return access.lock === true;
}

/** True when `access` lets the user do `op` ("read" | "write" | "call") on `member`. */
export function allows(access, member, op) {
  if (!access) return false;
  if (access.members === null) return true;
  const ops = access.members?.[member];
  return Array.isArray(ops) && ops.includes(op);
}

// RRError: how every failure reaches JS (the error name and message the service or the client core gave).

/** An RR error: `errorName` is the RR name ("RobotRaconteur.InvalidArgument", or a user exception name). */
export class RRError extends Error {
  constructor(errorName, message, code = 0) {
    super(message);
    this.name = "RRError";
    this.errorName = errorName;
    this.code = code;
  }
}

export function toRRError(e) {
  if (e instanceof RRError) return e;
  // an RR error from elsewhere (another copy of this module, a stand-in): its name is kept
  if (e && typeof e === "object" && typeof e.errorName === "string") return new RRError(e.errorName, e.message ?? "", e.code ?? 0);
  // (node's own errors have a text `code`, e.g. "ERR_MODULE_NOT_FOUND": not an RR error code)
  if (e && typeof e === "object" && typeof e.name === "string" && typeof e.code === "number")
    return new RRError(e.name, e.message ?? "", e.code);
  return new RRError("RobotRaconteur.UnknownError", String(e?.message ?? e));
}

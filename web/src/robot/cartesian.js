// Cartesian jogging (robdef jog_cartesian(SpatialVelocity{int32} max_velocity, double timeout, bool
// wait)): one axis at a time, as a map of kinematic chain 0 to a SpatialVelocity. The RobotInfo has
// no Cartesian velocity limit, so the full speed here is a fixed, slow one (the speed slider scales it).

/** Full-speed Cartesian jog: metres per second along an axis, radians per second about one. */
export const CARTESIAN_LINEAR_MPS = 0.1;
export const CARTESIAN_ANGULAR_RADPS = 0.5;

/** The six Cartesian axes: [{ id: "x", part: "linear", axis: "x", label: "X" }, ..., rz]. */
export const CARTESIAN_AXES = [
  ...["x", "y", "z"].map((a) => ({ id: a, part: "linear", axis: a, label: a.toUpperCase() })),
  ...["x", "y", "z"].map((a) => ({ id: `r${a}`, part: "angular", axis: a, label: `R${a.toUpperCase()}` })),
];

/**
 * The max_velocity argument of jog_cartesian for axis `id` ("x" … "rz") in `direction` (±1) at `speed`
 * (0..1): Map { 0 → {angular: {x,y,z}, linear: {x,y,z}} }. Throws RangeError for a bad axis, direction or speed.
 */
export function cartesianVelocity(id, direction, speed) {
  const a = CARTESIAN_AXES.find((x) => x.id === id);
  if (!a) throw new RangeError(`no Cartesian axis ${id}`);
  if (direction !== 1 && direction !== -1) throw new RangeError("direction must be +1 or -1");
  if (!(speed > 0 && speed <= 1)) throw new RangeError("speed must be in (0, 1]");
  const v = { angular: { x: 0, y: 0, z: 0 }, linear: { x: 0, y: 0, z: 0 } };
  v[a.part][a.axis] = direction * speed * (a.part === "linear" ? CARTESIAN_LINEAR_MPS : CARTESIAN_ANGULAR_RADPS);
  return new Map([[0, v]]);
}

/**
 * True when `error` (a failed jog_cartesian call) says the driver does not implement Cartesian jogging
 * (RobotRaconteur.NotImplementedError, as the abstract robot's base class answers): the robdef has no
 * capability flag for it, so the panel learns it from the first call and then hides the Cartesian buttons.
 */
export function isNotImplemented(error) {
  return error?.errorName === "RobotRaconteur.NotImplementedError";
}

// The joints of a robot from its RobotInfo (names, units, limits) and one row per joint of a
// RobotState: the position in the joint's own units (radians also in degrees), where it stands
// between its lower and upper limit, and a warning when it is near one of them.

/** A joint within this fraction of its range (upper − lower) from a limit is "near" it. */
export const NEAR_LIMIT_FRACTION = 0.05;

const DEG = 180 / Math.PI;
const SHORT_UNITS = { radian: "rad", degree: "°", meter: "m", millimeter: "mm", micrometer: "µm", nanometer: "nm", ticks_rot: "ticks", ticks_lin: "ticks" };

const num = (v) => (typeof v === "bigint" ? Number(v) : Number(v));
const finite = (v) => Number.isFinite(num(v));

/**
 * Joints of a RobotInfo value: [{ name, units (enum name: "radian", "meter", ...), lower, upper,
 * velocity, reducedVelocity }] (limits in the joint's units and units/s; NaN when the driver sent none).
 * `unitEnum`: the JointPositionUnits values [{name, value}]. A missing joint_info gives [].
 */
export function jointModel(info, unitEnum = []) {
  const joints = Array.isArray(info?.joint_info) ? info.joint_info : [];
  return joints.map((j, i) => {
    const lim = j?.joint_limits ?? {};
    const velocity = finite(lim.velocity) ? num(lim.velocity) : NaN;
    const reduced = finite(lim.reduced_velocity) && num(lim.reduced_velocity) > 0 ? num(lim.reduced_velocity) : velocity;
    return {
      name: j?.joint_identifier?.name || `joint_${i}`,
      units: unitEnum.find((e) => e.value === num(j?.default_units))?.name ?? "",
      lower: finite(lim.lower) ? num(lim.lower) : NaN,
      upper: finite(lim.upper) ? num(lim.upper) : NaN,
      velocity,
      reducedVelocity: reduced,
    };
  });
}

/**
 * Where `q` stands between `lower` and `upper`: { fraction (0 at lower, 1 at upper, clamped), near:
 * "lower" | "upper" | null } — near when within `nearFraction` of the range from that limit (or past
 * it). Without a valid range (NaN limits, upper ≤ lower): { fraction: null, near: null }.
 */
export function limitState(q, lower, upper, nearFraction = NEAR_LIMIT_FRACTION) {
  const range = upper - lower;
  if (!Number.isFinite(q) || !Number.isFinite(range) || range <= 0) return { fraction: null, near: null };
  const fraction = Math.min(1, Math.max(0, (q - lower) / range));
  const margin = range * nearFraction;
  const near = q <= lower + margin ? "lower" : q >= upper - margin ? "upper" : null;
  return { fraction, near };
}

/** "45.00° (0.7854 rad)" for radians, "0.1234 m" for metres, "12.5000" without units. */
export function positionText(v, units) {
  if (!Number.isFinite(v)) return String(v);
  if (units === "radian") return `${(v * DEG).toFixed(2)}° (${v.toFixed(4)} rad)`;
  const u = SHORT_UNITS[units];
  return `${v.toFixed(4)}${u ? ` ${u}` : ""}`;
}

/** A position in the joint's units as the page shows it for editing: degrees for radians, else as is. */
export function toDisplay(v, units) { return units === "radian" ? v * DEG : v; }
/** The inverse of toDisplay: a number typed in the displayed units to the joint's units. */
export function fromDisplay(v, units) { return units === "radian" ? v / DEG : v; }
/** The name of the displayed unit of a joint ("°" for radians). */
export function displayUnit(units) { return units === "radian" ? "°" : SHORT_UNITS[units] ?? ""; }

/**
 * One row per joint of RobotState `state`: [{ name, position (number, joint units), text, fraction,
 * near, velocity (text or ""), effort (text or "") }], named and bounded by `joints` (jointModel);
 * joints the model lacks are joint_<i> without limits. No joint_position: [].
 */
export function jointRows(state, joints = [], nearFraction = NEAR_LIMIT_FRACTION) {
  const q = state?.joint_position;
  if (!q || typeof q.length !== "number") return [];
  const same = (a) => (a && typeof a.length === "number" && a.length === q.length ? a : null);
  const qd = same(state.joint_velocity), tau = same(state.joint_effort);
  return Array.from(q, (x, i) => {
    const j = joints[i] ?? { name: `joint_${i}`, units: "", lower: NaN, upper: NaN };
    const position = num(x);
    const { fraction, near } = limitState(position, j.lower, j.upper, nearFraction);
    const u = SHORT_UNITS[j.units];
    return {
      name: j.name,
      position,
      text: positionText(position, j.units),
      fraction,
      near,
      velocity: qd ? `${num(qd[i]).toFixed(4)}${u ? ` ${u}/s` : ""}` : "",
      effort: tau ? num(tau[i]).toFixed(3) : "",
    };
  });
}

/**
 * The joint_velocity argument of jog_joint for jogging joint `index` in `direction` (+1 or −1) at
 * `speed` (a fraction 0..1) of its reduced velocity limit (the abstract robot refuses more than
 * joint_limits.reduced_velocity): a Float64Array with that joint's velocity only. Throws RangeError
 * for a bad index, direction or speed, or a joint without a velocity limit.
 */
export function jogVelocity(joints, index, direction, speed) {
  const j = joints[index];
  if (!j) throw new RangeError(`no joint ${index}`);
  if (direction !== 1 && direction !== -1) throw new RangeError("direction must be +1 or -1");
  if (!(speed > 0 && speed <= 1)) throw new RangeError("speed must be in (0, 1]");
  if (!(j.reducedVelocity > 0)) throw new RangeError(`joint ${j.name} has no velocity limit`);
  const v = new Float64Array(joints.length);
  v[index] = direction * speed * j.reducedVelocity;
  return v;
}

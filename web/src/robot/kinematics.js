// Forward kinematics of a com.robotraconteur.robotics.robot.Robot from its RobotInfo: each kinematic
// chain (RobotKinChainInfo) is a product of exponentials over its joint axes H and link vectors P,
// the way general_robotics_toolbox's fwdkin does it on the Robot that RobotRaconteurCompanion's
// RobotUtil.robot_info_to_rox_robot builds from the same RobotInfo (what the drivers on the official
// abstract robot report as kin_chain_tcp):
//   T = T_base · [P0, then per joint i: rotate about H[i] (revolute) or slide along H[i] (prismatic),
//       then P[i+1]] · T_flange · T_tcp
// with T_base the device_info's device_origin_pose, T_flange the chain's flange_pose and T_tcp the
// chain's current_tool.tcp when there is one. Positions in metres, quaternions w first; joint values
// in radians (revolute, continuous) or metres (prismatic).

/** com.robotraconteur.robotics.joints.JointType names by value (the wasm client gives enums as numbers). */
const JOINT_TYPES = ["unknown", "revolute", "continuous", "prismatic", "wheel", "screw", "other", "revolute2",
  "universal", "ball", "planar", "floating", "other_compound", "fixed"];

// ---- 3-vectors [x, y, z] and 3x3 rotation matrices (row-major arrays of 9 numbers)

const IDENTITY = Object.freeze([1, 0, 0, 0, 1, 0, 0, 0, 1]);
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);

/** R · v for a 3x3 matrix R and a 3-vector v. */
export function rotate(R, v) {
  return [
    R[0] * v[0] + R[1] * v[1] + R[2] * v[2],
    R[3] * v[0] + R[4] * v[1] + R[5] * v[2],
    R[6] * v[0] + R[7] * v[1] + R[8] * v[2],
  ];
}

/** A · B of two 3x3 matrices. */
export function matmul(A, B) {
  const C = new Array(9);
  for (let r = 0; r < 3; r++) {
    for (let c = 0; c < 3; c++) C[r * 3 + c] = A[r * 3] * B[c] + A[r * 3 + 1] * B[3 + c] + A[r * 3 + 2] * B[6 + c];
  }
  return C;
}

/** Rotation by `theta` radians about the unit axis k (Rodrigues' formula). */
export function axisAngleToMatrix(k, theta) {
  const [x, y, z] = k;
  const s = Math.sin(theta), c = 1 - Math.cos(theta);
  return [
    1 - c * (y * y + z * z), -s * z + c * x * y, s * y + c * x * z,
    s * z + c * x * y, 1 - c * (x * x + z * z), -s * x + c * y * z,
    -s * y + c * x * z, s * x + c * y * z, 1 - c * (x * x + y * y),
  ];
}

/** Rotation matrix of a unit quaternion [w, x, y, z]. */
export function quaternionToMatrix([w, x, y, z]) {
  return [
    1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
    2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
    2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
  ];
}

/** Unit quaternion [w, x, y, z] (w ≥ 0) of a rotation matrix. */
export function matrixToQuaternion(R) {
  const [m00, m01, m02, m10, m11, m12, m20, m21, m22] = R;
  const tr = m00 + m11 + m22;
  let q;
  // the largest of w, x, y, z divides: no cancellation near 180° turns
  if (tr > 0) {
    const s = 2 * Math.sqrt(1 + tr);
    q = [s / 4, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s];
  } else if (m00 > m11 && m00 > m22) {
    const s = 2 * Math.sqrt(1 + m00 - m11 - m22);
    q = [(m21 - m12) / s, s / 4, (m01 + m10) / s, (m02 + m20) / s];
  } else if (m11 > m22) {
    const s = 2 * Math.sqrt(1 + m11 - m00 - m22);
    q = [(m02 - m20) / s, (m01 + m10) / s, s / 4, (m12 + m21) / s];
  } else {
    const s = 2 * Math.sqrt(1 + m22 - m00 - m11);
    q = [(m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, s / 4];
  }
  const n = Math.hypot(...q) * (q[0] < 0 ? -1 : 1);
  return q.map((v) => v / n);
}

/** A rigid transform {R, p}: R a 3x3 matrix, p a 3-vector in metres. */
const IDENTITY_TRANSFORM = Object.freeze({ R: IDENTITY, p: Object.freeze([0, 0, 0]) });
const compose = (a, b) => ({ R: matmul(a.R, b.R), p: add(a.p, rotate(a.R, b.p)) });
const applyTo = (t, v) => add(t.p, rotate(t.R, v));

// ---- reading RobotInfo values as the wasm client gives them (namedarrays as objects; also arrays)

/** [x, y, z] of a Vector3/Point value ({x, y, z} or 3 numbers), or null. */
function xyz(v) {
  const a = v && (ArrayBuffer.isView(v) || Array.isArray(v)) ? Array.from(v) : v ? [v.x, v.y, v.z] : null;
  return a && a.length === 3 && a.every((n) => typeof n === "number" && Number.isFinite(n)) ? a : null;
}

/** Unit [w, x, y, z] of a Quaternion value ({w, x, y, z} or 4 numbers), or null when zero or not numbers. */
function wxyz(v) {
  const a = v && (ArrayBuffer.isView(v) || Array.isArray(v)) ? Array.from(v) : v ? [v.w, v.x, v.y, v.z] : null;
  if (!a || a.length !== 4 || !a.every((n) => typeof n === "number" && Number.isFinite(n))) return null;
  const n = Math.hypot(...a);
  return n > 0 ? a.map((x) => x / n) : null;
}

/** A list of Vector3 values: an Array of objects/arrays, or a flat numeric array of 3n numbers. */
function vectorList(v) {
  if (ArrayBuffer.isView(v) || (Array.isArray(v) && v.every((n) => typeof n === "number"))) {
    if (v.length % 3) return null;
    const out = [];
    for (let i = 0; i < v.length; i += 3) out.push(xyz([v[i], v[i + 1], v[i + 2]]));
    return out.every(Boolean) ? out : null;
  }
  if (!Array.isArray(v)) return null;
  const out = v.map(xyz);
  return out.every(Boolean) ? out : null;
}

/** {R, p} of a Pose value ({orientation, position} or 7 numbers w x y z x y z); `fallback` when absent. */
function poseTransform(v, what, fallback = IDENTITY_TRANSFORM) {
  if (v === null || v === undefined) return fallback;
  if (ArrayBuffer.isView(v) || Array.isArray(v)) v = { orientation: Array.from(v).slice(0, 4), position: Array.from(v).slice(4) };
  const q = wxyz(v.orientation), p = xyz(v.position);
  if (!q || !p) throw new Error(`${what} is not a pose (a unit quaternion w, x, y, z and a position x, y, z)`);
  return { R: quaternionToMatrix(q), p };
}

/** {R, p} of a Transform value ({rotation, translation} or 7 numbers), or null when absent. */
function transformValue(v, what) {
  if (v === null || v === undefined) return null;
  if (ArrayBuffer.isView(v) || Array.isArray(v)) v = { rotation: Array.from(v).slice(0, 4), translation: Array.from(v).slice(4) };
  const q = wxyz(v.rotation), p = xyz(v.translation);
  if (!q || !p) throw new Error(`${what} is not a transform (a unit quaternion w, x, y, z and a translation x, y, z)`);
  return { R: quaternionToMatrix(q), p };
}

function jointTypeName(t) {
  return typeof t === "string" ? t : JOINT_TYPES[t] ?? `joint type ${t}`;
}

/**
 * The kinematic model of chain `index` of a RobotInfo value, checked once for forwardKinematics.
 * Returns { name, jointNumbers: number[], joints: [{ axis: [x,y,z], type: "revolute"|"continuous"|
 * "prismatic", name }], links: [x,y,z][] (P, one more than joints, metres), base, flange, tool:
 * {R, p} | null }. `tool` is the chain's current_tool.tcp, `base` the device_info's device_origin_pose.
 * joint_numbers defaults to 0, 1, ... when the chain has none; flange_pose to the identity.
 * Throws an Error saying what is wrong: no such chain, H or P missing or of the wrong length, a joint
 * number outside joint_info, a joint type other than revolute, continuous or prismatic, a zero axis.
 */
export function chainModel(info, index = 0) {
  const chains = Array.isArray(info?.chains) ? info.chains : null;
  if (!chains?.length) throw new Error("robot_info has no kinematic chains");
  const chain = chains[index];
  if (!chain || typeof chain !== "object") throw new Error(`robot_info has no kinematic chain ${index}`);
  const name = chain.kin_chain_identifier?.name || `chain ${index}`;
  const H = vectorList(chain.H), P = vectorList(chain.P);
  if (!H?.length) throw new Error(`${name}: H (the joint axes) is missing or not a list of vectors`);
  if (!P) throw new Error(`${name}: P (the link vectors) is missing or not a list of vectors`);
  if (P.length !== H.length + 1) throw new Error(`${name}: P has ${P.length} vectors, H ${H.length} (P needs one more)`);
  const jointInfo = Array.isArray(info.joint_info) ? info.joint_info : [];
  const numbers = chain.joint_numbers?.length ? Array.from(chain.joint_numbers, Number) : H.map((_, i) => i);
  if (numbers.length !== H.length) throw new Error(`${name}: ${numbers.length} joint_numbers for ${H.length} axes in H`);
  const joints = H.map((axis, i) => {
    const n = numbers[i];
    if (!Number.isInteger(n) || n < 0 || n >= jointInfo.length) {
      throw new Error(`${name}: joint number ${n} is not one of the ${jointInfo.length} joints of joint_info`);
    }
    const type = jointTypeName(jointInfo[n]?.joint_type);
    if (!["revolute", "continuous", "prismatic"].includes(type)) throw new Error(`${name}: joint ${n} is ${type}: only revolute, continuous and prismatic joints are drawn`);
    const length = norm(axis);
    if (!(length > 1e-9)) throw new Error(`${name}: the axis H[${i}] is zero`);
    // the toolbox refuses axes that are not unit vectors (the driver would not start): normalised here
    return { axis: scale(axis, 1 / length), type, name: jointInfo[n]?.joint_identifier?.name || `joint_${n}` };
  });
  const base = poseTransform(info.device_info?.device_origin_pose?.pose, "device_info.device_origin_pose");
  const flange = poseTransform(chain.flange_pose, `${name}: flange_pose`);
  const tool = transformValue(chain.current_tool?.tcp, `${name}: current_tool.tcp`);
  return { name, jointNumbers: numbers, joints, links: P, base, flange, tool };
}

/**
 * Every chain of a RobotInfo value: { chains: model[] (see chainModel), errors: string[] } (one error
 * per chain that cannot be used; never throws).
 */
export function robotModel(info) {
  const chains = [], errors = [];
  const n = Array.isArray(info?.chains) ? info.chains.length : 0;
  if (!n) errors.push("robot_info has no kinematic chains");
  for (let i = 0; i < n; i++) {
    try {
      chains.push(chainModel(info, i));
    } catch (e) {
      errors.push(e.message);
    }
  }
  return { chains, errors };
}

/** A Pose-like result {position: {x, y, z} (m), orientation: {w, x, y, z}} of a transform {R, p}. */
export function transformToPose({ R, p }) {
  const [w, x, y, z] = matrixToQuaternion(R);
  return { position: { x: p[0], y: p[1], z: p[2] }, orientation: { w, x, y, z } };
}

/**
 * Forward kinematics of one chain (a chainModel) at the robot's joint vector `q` (all joints of the
 * robot, indexed by the chain's joint_numbers; radians or metres). Returns
 *   { tcp: Pose — what the driver reports as kin_chain_tcp (flange, then the current tool's tcp),
 *     flange: Pose — the tool flange, without the tool,
 *     joints: [{ position: [x,y,z], axis: [x,y,z] unit, type, name }] — each joint's origin and axis
 *       in the base frame, before the joint moves (a prismatic joint slides away from it),
 *     points: [x,y,z][] — the polyline of the chain's links: base origin, then the end of each P
 *       vector and of each prismatic slide, ending at the flange,
 *     flangeTransform, tcpTransform: {R, p} }
 * in the robot's base frame (device_origin_pose applied). Throws when q is too short or not numbers.
 */
export function forwardKinematics(model, q) {
  const values = model.jointNumbers.map((n) => Number(q?.[n]));
  if (!q || typeof q.length !== "number" || values.some((v) => !Number.isFinite(v))) {
    throw new Error(`${model.name}: the joint vector has no number for every joint ${model.jointNumbers.join(", ")}`);
  }
  let R = IDENTITY, p = model.links[0];
  const world = (v) => applyTo(model.base, v);
  const points = [world([0, 0, 0]), world(p)];
  const joints = [];
  model.joints.forEach((j, i) => {
    const axis = rotate(model.base.R, rotate(R, j.axis));
    joints.push({ position: world(p), axis: scale(axis, 1 / norm(axis)), type: j.type, name: j.name });
    if (j.type === "prismatic") {
      p = add(p, scale(rotate(R, j.axis), values[i]));
      points.push(world(p));
    } else {
      R = matmul(R, axisAngleToMatrix(j.axis, values[i]));
    }
    p = add(p, rotate(R, model.links[i + 1]));
    points.push(world(p));
  });
  const flangeTransform = compose(model.base, compose({ R, p }, model.flange));
  const tcpTransform = model.tool ? compose(flangeTransform, model.tool) : flangeTransform;
  points.push(flangeTransform.p);
  return { tcp: transformToPose(tcpTransform), flange: transformToPose(flangeTransform), joints, points, flangeTransform, tcpTransform };
}

/**
 * How far apart two poses are: { distance: metres between the positions, angle: radians of the
 * rotation from one orientation to the other }. Poses as forwardKinematics gives them or as the
 * wasm client gives a Pose ({orientation: {w, x, y, z}, position: {x, y, z}}).
 */
export function poseDifference(a, b) {
  const pa = xyz(a?.position), pb = xyz(b?.position), qa = wxyz(a?.orientation), qb = wxyz(b?.orientation);
  if (!pa || !pb || !qa || !qb) throw new Error("poseDifference: not a pose");
  const dot = Math.abs(qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3]);
  return { distance: norm([pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]]), angle: 2 * Math.acos(Math.min(1, dot)) };
}

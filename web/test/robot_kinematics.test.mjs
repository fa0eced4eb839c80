// Forward kinematics of web/src/robot/kinematics.js against general_robotics_toolbox (rox.fwdkin), the
// library the official abstract robot driver computes kin_chain_tcp with: 50 random joint vectors on a
// 6-axis arm (flange rotated, a tool tcp, the robot's origin pose moved) and on a chain with prismatic
// joints picked out of a longer joint vector by joint_numbers; within 1 mm and 0.1°. The expected
// poses come from the project's .venv python at test time (the rox Robot built as
// RobotRaconteurCompanion's robot_info_to_rox_robot builds it: H, P, joint types, T_flange, T_base;
// the tool's tcp after it, as the abstract robot applies current_tool); skipped when rox is missing.
// Then the errors: what a RobotInfo the view cannot use says.
import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { chainModel, robotModel, forwardKinematics, poseDifference, matrixToQuaternion, quaternionToMatrix } from "../src/robot/kinematics.js";

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../..");
const python = path.join(root, ".venv/bin/python");

const v = (x, y, z) => ({ x, y, z });
const joint = (name, type, lower, upper) => ({ joint_identifier: { name }, joint_type: type, joint_limits: { lower, upper } });
const REVOLUTE = 1, CONTINUOUS = 2, PRISMATIC = 3;

/** A 6-axis arm (the usual z, y, y, x, y, x axes), flange turned 90° about y, a tool, a moved origin. */
const ARM6 = {
  device_info: { device_origin_pose: { pose: { orientation: { w: Math.cos(0.3), x: 0, y: 0, z: Math.sin(0.3) }, position: v(0.5, -0.2, 0.1) } } },
  joint_info: [
    joint("j1", REVOLUTE, -3, 3), joint("j2", REVOLUTE, -2, 2), joint("j3", REVOLUTE, -2, 2),
    joint("j4", CONTINUOUS, -3, 3), joint("j5", REVOLUTE, -2, 2), joint("j6", REVOLUTE, -3, 3),
  ],
  chains: [{
    kin_chain_identifier: { name: "arm6" },
    H: [v(0, 0, 1), v(0, 1, 0), v(0, 1, 0), v(1, 0, 0), v(0, 1, 0), v(1, 0, 0)],
    P: [v(0, 0, 0.399), v(0, 0, 0), v(0, 0, 0.448), v(0, 0, 0.042), v(0.451, 0, 0), v(0.082, 0, 0), v(0, 0, 0)],
    joint_numbers: Uint32Array.of(0, 1, 2, 3, 4, 5),
    flange_pose: { orientation: { w: Math.SQRT1_2, x: 0, y: Math.SQRT1_2, z: 0 }, position: v(0.01, 0, 0) },
    current_tool: { tcp: { rotation: { w: Math.cos(0.2), x: Math.sin(0.2), y: 0, z: 0 }, translation: v(0, 0.02, 0.15) } },
  }],
};

/** A chain of 4 of the robot's 5 joints: revolute, prismatic (z), revolute, prismatic (x). */
const PRISMATIC4 = {
  joint_info: [
    joint("rail", PRISMATIC, 0, 1), joint("spare", REVOLUTE, -1, 1), joint("lift", PRISMATIC, -0.2, 0.4),
    joint("turn", REVOLUTE, -3, 3), joint("reach", PRISMATIC, 0, 0.3),
  ],
  chains: [{
    kin_chain_identifier: { name: "slider" },
    H: [v(0, 0, 1), v(0, 0, 1), v(0, 0, 1), v(1, 0, 0)],
    P: [v(0, 0, 0.2), v(0.3, 0, 0), v(0, 0, 0.1), v(0.25, 0.05, 0), v(0.1, 0, -0.05)],
    joint_numbers: [1, 2, 3, 4],
    flange_pose: { orientation: { w: 0.9, x: 0.1, y: -0.3, z: 0.2 }, position: v(0, 0, -0.04) },  // not normalised
  }],
};
PRISMATIC4.joint_info[1].joint_type = REVOLUTE;

/** Deterministic joint vectors inside the limits (mulberry32). */
function randomVectors(info, count, seed) {
  let a = seed >>> 0;
  const rnd = () => { a = (a + 0x6d2b79f5) >>> 0; let t = Math.imul(a ^ (a >>> 15), 1 | a); t ^= t + Math.imul(t ^ (t >>> 7), 61 | t); return ((t ^ (t >>> 14)) >>> 0) / 4294967296; };
  return Array.from({ length: count }, () => Float64Array.from(info.joint_info, (j) => j.joint_limits.lower + rnd() * (j.joint_limits.upper - j.joint_limits.lower)));
}

// The toolbox side: the rox Robot as robot_info_to_rox_robot makes it (its joint types: 0 revolute,
// 1 prismatic), fwdkin, then the tool's tcp as the abstract robot's _calc_endpoint_pose applies it.
const ROX_SCRIPT = String.raw`
import json, sys
import numpy as np
import general_robotics_toolbox as rox
tf = lambda t: rox.Transform(rox.q2R(np.array(t["q"]) / np.linalg.norm(t["q"])), np.array(t["p"]))
result = []
for d in json.load(sys.stdin):
    robot = rox.Robot(np.array(d["H"]).T, np.array(d["P"]).T, d["types"], T_flange=tf(d["flange"]),
                      T_base=tf(d["base"]) if d["base"] else None)
    out = []
    for q in d["qs"]:
        T = rox.fwdkin(robot, np.array(q))
        if d["tool"]:
            T = T * tf(d["tool"])
        out.append({"p": list(T.p), "q": list(rox.R2q(T.R))})
    result.append(out)
print(json.dumps(result))
`;

/** rox's tcp poses for [{ info, qs }] (one python process): [[Pose, ...], ...]. */
function roxPoses(cases) {
  const arr = (o) => [o.x, o.y, o.z];
  const quat = (o) => [o.w, o.x, o.y, o.z];
  const input = cases.map(({ info, qs }) => {
    const c = info.chains[0], origin = info.device_info?.device_origin_pose?.pose;
    return {
      H: c.H.map(arr), P: c.P.map(arr),
      types: Array.from(c.joint_numbers, (n) => (info.joint_info[n].joint_type === PRISMATIC ? 1 : 0)),
      flange: { q: quat(c.flange_pose.orientation), p: arr(c.flange_pose.position) },
      tool: c.current_tool ? { q: quat(c.current_tool.tcp.rotation), p: arr(c.current_tool.tcp.translation) } : null,
      base: origin ? { q: quat(origin.orientation), p: arr(origin.position) } : null,
      qs: qs.map((q) => Array.from(c.joint_numbers, (n) => q[n])),
    };
  });
  const out = JSON.parse(execFileSync(python, ["-c", ROX_SCRIPT], { input: JSON.stringify(input), encoding: "utf8" }));
  return out.map((poses) => poses.map((r) => ({ position: v(...r.p), orientation: { w: r.q[0], x: r.q[1], y: r.q[2], z: r.q[3] } })));
}

/** rox's poses of every geometry, or { missing: why } when the .venv has no toolbox (then skipped). */
function runRox() {
  if (!fs.existsSync(python)) return { missing: `no ${python} (run ./scripts/setup.sh)` };
  try {
    return { poses: roxPoses(GEOMETRIES.map(([, info, seed]) => ({ info, qs: randomVectors(info, 50, seed) }))) };
  } catch (e) {
    const last = String(e.stderr ?? e.message).trim().split("\n").pop();
    if (/ModuleNotFoundError|ImportError/.test(last)) return { missing: `general_robotics_toolbox not importable in .venv: ${last} (run ./scripts/setup.sh)` };
    throw e;
  }
}

const GEOMETRIES = [["6-axis arm", ARM6, 42], ["chain with prismatic joints", PRISMATIC4, 7]];
const rox = runRox();   // one python run for both geometries (its start is the slow part)
GEOMETRIES.forEach(([name, info, seed], k) => {
  test(`${name}: 50 random joint vectors match rox.fwdkin within 1 mm and 0.1°`, { skip: rox.missing ?? false }, () => {
    const qs = randomVectors(info, 50, seed);
    const expected = rox.poses[k];
    const model = chainModel(info, 0);
    let worst = { distance: 0, angle: 0 };
    qs.forEach((q, i) => {
      const d = poseDifference(forwardKinematics(model, q).tcp, expected[i]);
      assert.ok(d.distance < 1e-3 && d.angle < (0.1 * Math.PI) / 180,
        `q = [${Array.from(q).map((x) => x.toFixed(4))}]: ${(d.distance * 1000).toFixed(3)} mm, ${((d.angle * 180) / Math.PI).toFixed(3)}° from rox`);
      worst = { distance: Math.max(worst.distance, d.distance), angle: Math.max(worst.angle, d.angle) };
    });
    // and the results are not all alike (the joints do move the tool)
    const spread = poseDifference(expected[0], expected[1]);
    assert.ok(spread.distance > 0.01, `two random vectors give poses ${spread.distance} m apart`);
    console.log(`${name}: worst of 50: ${worst.distance.toExponential(2)} m, ${worst.angle.toExponential(2)} rad`);
  });
});

test("the drawing data: joint origins, axes, link polyline ending at the flange", () => {
  const model = chainModel(PRISMATIC4, 0);
  const q = [0.5, 0, 0.1, Math.PI / 2, 0.2];   // joint 0 (rail) is not in the chain: ignored
  const fk = forwardKinematics(model, q);
  assert.equal(fk.joints.length, 4);
  assert.deepEqual(fk.joints.map((j) => j.type), ["revolute", "prismatic", "revolute", "prismatic"]);
  assert.deepEqual(fk.joints.map((j) => j.name), ["spare", "lift", "turn", "reach"]);
  const near = (a, b) => a.every((x, i) => Math.abs(x - b[i]) < 1e-12);
  assert.ok(near(fk.joints[0].position, [0, 0, 0.2]));
  assert.ok(near(fk.joints[1].position, [0.3, 0, 0.2]));
  assert.ok(near(fk.joints[2].position, [0.3, 0, 0.4]), String(fk.joints[2].position));   // lifted by 0.1 m, then P[2]
  // the turn by 90° about z points the reach axis (x) along y
  assert.ok(near(fk.joints[3].axis, [0, 1, 0]), String(fk.joints[3].axis));
  assert.ok(near(fk.joints[3].position, [0.3 - 0.05, 0.25, 0.4]), String(fk.joints[3].position));
  // base, P0, P1, slide, P2, P3, slide, P4, flange
  assert.equal(fk.points.length, 9);
  assert.ok(near(fk.points.at(-1), [0.25, 0.25 + 0.2 + 0.1, 0.4 - 0.05 - 0.04]), String(fk.points.at(-1)));
  // no tool: tcp is the flange
  assert.deepEqual(fk.tcp, fk.flange);
});

test("quaternion ↔ matrix round trip, also near 180° turns", () => {
  for (const q of [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1], [0.01, 0.7, -0.7, 0.1], [0.5, 0.5, 0.5, 0.5]]) {
    const n = Math.hypot(...q), u = q.map((x) => x / n);
    const back = matrixToQuaternion(quaternionToMatrix(u));
    const dot = Math.abs(u.reduce((s, x, i) => s + x * back[i], 0));
    assert.ok(Math.abs(dot - 1) < 1e-12, `${q} -> ${back}`);
    assert.ok(back[0] >= 0);
  }
});

test("a RobotInfo the view cannot use: a clear error, never a crash", () => {
  const bad = (mutate) => { const info = structuredClone(PRISMATIC4); mutate(info); return info; };
  assert.throws(() => chainModel({}, 0), /no kinematic chains/);
  assert.throws(() => chainModel(PRISMATIC4, 1), /no kinematic chain 1/);
  assert.throws(() => chainModel(bad((i) => delete i.chains[0].H), 0), /slider: H \(the joint axes\) is missing/);
  assert.throws(() => chainModel(bad((i) => { i.chains[0].P = null; }), 0), /P \(the link vectors\) is missing/);
  assert.throws(() => chainModel(bad((i) => i.chains[0].P.pop()), 0), /P has 4 vectors, H 4 \(P needs one more\)/);
  assert.throws(() => chainModel(bad((i) => { i.chains[0].H[1] = { x: 0, y: 0 }; }), 0), /H \(the joint axes\) is missing or not a list of vectors/);
  assert.throws(() => chainModel(bad((i) => { i.chains[0].joint_numbers = [1, 2, 3, 9]; }), 0), /joint number 9 is not one of the 5 joints/);
  assert.throws(() => chainModel(bad((i) => { i.chains[0].joint_numbers = [1, 2]; }), 0), /2 joint_numbers for 4 axes/);
  assert.throws(() => chainModel(bad((i) => { i.joint_info[3].joint_type = 6; }), 0), /joint 3 is other: only revolute, continuous and prismatic/);
  assert.throws(() => chainModel(bad((i) => { i.chains[0].H[0] = v(0, 0, 0); }), 0), /the axis H\[0\] is zero/);
  assert.throws(() => chainModel(bad((i) => { i.chains[0].flange_pose.orientation = { w: 0, x: 0, y: 0, z: 0 }; }), 0), /flange_pose is not a pose/);
  assert.throws(() => forwardKinematics(chainModel(PRISMATIC4, 0), [0, 1]), /no number for every joint 1, 2, 3, 4/);
  assert.throws(() => forwardKinematics(chainModel(PRISMATIC4, 0), null), /no number for every joint/);
  // robotModel collects the errors instead of throwing
  const r = robotModel({ joint_info: [], chains: [{ kin_chain_identifier: { name: "old" }, H: [] }] });
  assert.deepEqual(r.chains, []);
  assert.match(r.errors[0], /old: H/);
  assert.deepEqual(robotModel(null).errors, ["robot_info has no kinematic chains"]);
  // flat arrays as the wire may carry them (namedarray arrays as numbers) and no joint_numbers / flange_pose
  const flat = chainModel({ joint_info: [joint("a", "revolute", -1, 1)], chains: [{ H: Float64Array.of(0, 0, 1), P: Float64Array.of(0, 0, 1, 1, 0, 0) }] }, 0);
  const fk = forwardKinematics(flat, [Math.PI / 2]);
  assert.ok(Math.abs(fk.tcp.position.y - 1) < 1e-12 && Math.abs(fk.tcp.position.z - 1) < 1e-12, JSON.stringify(fk.tcp));
});

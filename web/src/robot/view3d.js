// A three.js view of a com.robotraconteur.robotics.robot.Robot drawn from its RobotInfo alone (no
// meshes): per kinematic chain, each link a cylinder between consecutive joint origins (a chain's
// links are straight segments), each joint's axis (revolute: an orange disc around the axis;
// prismatic: a blue bar along it), the tool flange as a small x/y/z triad (red/green/blue), and the
// pose the driver reports (kin_chain_tcp) as a thinner triad, so a RobotInfo that disagrees with the
// driver shows. A ground grid in the base's x-y plane (z up). Orbit, pan and zoom with the mouse.
// update() may be called at the wire's rate: the view renders at most once per animation frame, and
// only when a joint, the reported pose, the camera or the size changed.

import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { robotModel, forwardKinematics } from "./kinematics.js";

const COLORS = { link: 0x8a96a8, revolute: 0xf29c38, prismatic: 0x3a7bd5, base: 0x556070, background: 0xf4f6f9 };
const UP = new THREE.Vector3(0, 1, 0);   // the axis three.js builds cylinders and boxes along

/** Rough size of the robot in metres (sum of the link vectors and prismatic ranges), for scaling the drawing. */
function robotSize(models, info) {
  let size = 0;
  for (const m of models) {
    let reach = m.links.reduce((s, p) => s + Math.hypot(...p), 0);
    m.joints.forEach((j, i) => {
      const lim = info?.joint_info?.[m.jointNumbers[i]]?.joint_limits;
      if (j.type === "prismatic" && lim) reach += Math.max(Math.abs(lim.lower) || 0, Math.abs(lim.upper) || 0);
    });
    size = Math.max(size, reach);
  }
  return size > 1e-6 && Number.isFinite(size) ? size : 1;
}

/** A triad of x/y/z arrows (red, green, blue) of `length`, made of lines (cheap, readable at any zoom). */
function triad(length, opacity = 1) {
  const t = new THREE.AxesHelper(length);
  if (opacity < 1) Object.assign(t.material, { transparent: true, opacity });
  return t;
}

/** Sets mesh (built along +y, height 1) to span from a to b ([x,y,z]); hidden when a and b meet. */
function placeBetween(mesh, a, b) {
  const from = new THREE.Vector3(...a), dir = new THREE.Vector3(...b).sub(from);
  const length = dir.length();
  mesh.visible = length > 1e-9;
  if (!mesh.visible) return;
  mesh.position.copy(from).addScaledVector(dir, 0.5);
  mesh.quaternion.setFromUnitVectors(UP, dir.divideScalar(length));
  mesh.scale.set(1, length, 1);
}

/**
 * Mounts a 3D view of the robot described by `info` (a RobotInfo value as the wasm client gives it)
 * in `parent`. Returns { el, ok, message, update(q, reportedTcp), dispose() }:
 *   update(q, reportedTcp): q the robot's joint vector (RobotState.joint_position: radians, metres),
 *     reportedTcp optional (RobotState.kin_chain_tcp: Pose per chain); cheap, call at any rate.
 *   ok false: the RobotInfo cannot be drawn (no chains, H or P missing or of the wrong length, an
 *     unsupported joint type, ...) or WebGL is not available; `message` says why and is shown instead.
 * The element carries, for tests and tools, data-state ("ready" | "message"), data-renders (frames
 * drawn), data-q (the joint vector drawn, JSON), data-tcp and data-reported-tcp (per chain
 * [x, y, z, qw, qx, qy, qz] of the pose computed from RobotInfo and of the pose the driver sent with
 * the same joint vector, JSON).
 */
export function createRobotView3d(parent, info, { height = 320 } = {}) {
  const el = document.createElement("div");
  el.className = "robot-view3d";
  el.dataset.panelPart = "robot-3d";
  parent.append(el);
  const showMessage = (text) => {
    el.dataset.state = "message";
    const p = document.createElement("p");
    p.className = "robot-view3d-message";
    p.textContent = `3D view: ${text}`;
    el.replaceChildren(p);
    return { el, ok: false, message: text, update() {}, dispose() { el.remove(); } };
  };

  const { chains: models, errors } = robotModel(info);
  if (!models.length) return showMessage(errors[0] || "robot_info has no kinematic chain that can be drawn");

  let renderer;
  const canvas = document.createElement("canvas");
  try {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    return showMessage(`WebGL is not available in this browser (${e?.message || e})`);
  }
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.setClearColor(COLORS.background);
  el.append(canvas);
  if (errors.length) {
    const note = document.createElement("p");
    note.className = "robot-view3d-message";
    note.textContent = `3D view: not drawn: ${errors.join("; ")}`;
    el.append(note);
  }
  el.dataset.state = "ready";
  canvas.style.height = `${height}px`;

  const size = robotSize(models, info);
  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(size, -size, 2 * size);
  scene.add(sun);
  const grid = new THREE.GridHelper(3 * size, 12, 0x9aa4b2, 0xd0d6de);
  grid.rotation.x = Math.PI / 2;   // the grid in the x-y plane: robots are z up
  scene.add(grid, triad(size * 0.15, 0.5));

  const radius = size * 0.025;
  const unitCylinder = new THREE.CylinderGeometry(radius, radius, 1, 16);
  const revoluteDisc = new THREE.CylinderGeometry(radius * 2.2, radius * 2.2, radius * 2.4, 24);
  const prismaticBar = new THREE.BoxGeometry(radius * 2.8, radius * 7, radius * 2.8);
  const materials = Object.fromEntries(["link", "revolute", "prismatic"].map((k) => [k, new THREE.MeshStandardMaterial({ color: COLORS[k], roughness: 0.6 })]));
  const baseMesh = new THREE.Mesh(new THREE.CylinderGeometry(radius * 3, radius * 3.5, radius * 2, 24), new THREE.MeshStandardMaterial({ color: COLORS.base }));
  baseMesh.rotation.x = Math.PI / 2;
  scene.add(baseMesh);

  // one set of meshes per chain, built once (the number of links never changes) and moved by update()
  const drawn = models.map((model) => {
    const added = (o) => { scene.add(o); return o; };
    const fk0 = forwardKinematics(model, new Array(Math.max(...model.jointNumbers) + 1).fill(0));
    const links = fk0.points.slice(1).map(() => added(new THREE.Mesh(unitCylinder, materials.link)));
    const joints = model.joints.map((j) => (j.type === "prismatic"
      ? added(new THREE.Mesh(prismaticBar, materials.prismatic))
      : added(new THREE.Mesh(revoluteDisc, materials.revolute))));
    const flange = triad(size * 0.12);
    const reported = triad(size * 0.2, 0.45);
    reported.visible = false;
    scene.add(flange, reported);
    return { model, links, joints, flange, reported, tcp: null };
  });

  const camera = new THREE.PerspectiveCamera(45, 1, size / 100, size * 50);
  camera.up.set(0, 0, 1);
  camera.position.set(size * 0.95, -size * 1.25, size * 0.8);
  const controls = new OrbitControls(camera, canvas);
  controls.target.set(size * 0.1, 0, size * 0.25);
  controls.update();

  let q = null, reportedTcp = null, changed = true, frame = 0, renders = 0, disposed = false, drawnSize = { w: 0, h: 0 };
  const invalidate = () => { if (!frame && !disposed) frame = requestAnimationFrame(render); };
  controls.addEventListener("change", invalidate);

  function applyJoints() {
    const poses = [];
    for (const [c, d] of drawn.entries()) {
      let fk;
      try {
        fk = forwardKinematics(d.model, q ?? []);
      } catch {
        fk = null;   // no joint vector yet (or a short one): keep the last drawing
      }
      if (fk) {
        fk.points.slice(1).forEach((b, i) => placeBetween(d.links[i], fk.points[i], b));
        fk.joints.forEach((j, i) => {
          d.joints[i].position.set(...j.position);
          d.joints[i].quaternion.setFromUnitVectors(UP, new THREE.Vector3(...j.axis));
        });
        const { position: p, orientation: o } = fk.flange;
        d.flange.position.set(p.x, p.y, p.z);
        d.flange.quaternion.set(o.x, o.y, o.z, o.w);
        d.tcp = fk.tcp;
      }
      const r = reportedTcp?.[c];
      d.reported.visible = !!(r?.position && r?.orientation);
      if (d.reported.visible) {
        d.reported.position.set(r.position.x, r.position.y, r.position.z);
        d.reported.quaternion.set(r.orientation.x, r.orientation.y, r.orientation.z, r.orientation.w).normalize();
      }
      poses.push(d.tcp);
    }
    const flat = (p) => (p ? [p.position.x, p.position.y, p.position.z, p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z] : null);
    el.dataset.q = JSON.stringify(q ? Array.from(q) : null);
    el.dataset.tcp = JSON.stringify(poses.map(flat));
    el.dataset.reportedTcp = JSON.stringify(drawn.map((_, c) => flat(reportedTcp?.[c]?.position ? reportedTcp[c] : null)));
  }

  function render() {
    frame = 0;
    if (disposed) return;
    if (changed) {
      changed = false;
      applyJoints();
    }
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (w && h && (w !== drawnSize.w || h !== drawnSize.h)) {
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
    }
    drawnSize = { w, h };
    renderer.render(scene, camera);
    el.dataset.renders = String(++renders);
  }

  // a new frame only when the size differs from the one drawn (the observer also reports the first size)
  const resize = new ResizeObserver(() => {
    if (canvas.clientWidth !== drawnSize.w || canvas.clientHeight !== drawnSize.h) invalidate();
  });
  resize.observe(canvas);
  invalidate();

  const same = (a, b) => a === b || (a && b && a.length === b.length && Array.prototype.every.call(a, (x, i) => x === b[i]));
  const poseNumbers = (p) => [p?.position?.x, p?.position?.y, p?.position?.z, p?.orientation?.w, p?.orientation?.x, p?.orientation?.y, p?.orientation?.z];
  const samePoses = (a, b) => a === b || (Array.isArray(a) && Array.isArray(b) && a.length === b.length
    && a.every((p, i) => same(poseNumbers(p), poseNumbers(b[i]))));

  return {
    el,
    ok: true,
    message: errors.length ? `not drawn: ${errors.join("; ")}` : null,
    update(joints, reported = null) {
      if (disposed) return;
      const nextQ = joints && typeof joints.length === "number" ? Float64Array.from(joints, Number) : null;
      const nextR = Array.isArray(reported) ? reported : null;
      if (same(nextQ, q) && samePoses(nextR, reportedTcp)) return;
      q = nextQ;
      reportedTcp = nextR;
      changed = true;
      invalidate();
    },
    dispose() {
      if (disposed) return;
      disposed = true;
      if (frame) cancelAnimationFrame(frame);
      resize.disconnect();
      controls.dispose();
      scene.traverse((o) => {
        o.geometry?.dispose();
        for (const m of [o.material].flat()) m?.dispose();
      });
      renderer.dispose();
      renderer.forceContextLoss();   // browsers cap live WebGL contexts: give this one back now
      el.remove();
    },
  };
}

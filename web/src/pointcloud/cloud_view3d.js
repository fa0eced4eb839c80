// A three.js view of a point cloud (the point cloud panel's): the points as one THREE.Points of the
// colours colorCloud gave (passed through as they are: no lighting, no colour-space conversion, so a
// point of the device's colour 0xE62828 is drawn in exactly that colour), over a grid in the sensor's
// x-y plane (z up) and its x/y/z triad. Orbit, pan and zoom with the mouse; the camera is fitted to the
// first cloud's bounds and again on reset(). show() may be called at any rate: the view draws at most
// once per animation frame, and only when the cloud, the camera or its size changed.

import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";

const BACKGROUND = 0xf4f6f9;

/**
 * Mounts the view in `parent`. Returns { el, ok, message, show(drawn), reset(), dispose() }:
 *   show(drawn): a drawable cloud (colorCloud's form: count, positions, colors, min, max)
 *   ok false: no WebGL in this browser (`message` says so, shown instead).
 * The element carries data-state ("ready" | "message"), data-renders (frames drawn), data-points
 * (points in the drawn cloud) for tests and tools.
 */
export function createCloudView3d(parent, { height = 360, pointSize = 3 } = {}) {
  const el = document.createElement("div");
  el.className = "cloud-view3d";
  el.dataset.panelPart = "cloud-3d";
  parent.append(el);
  let renderer;
  const canvas = document.createElement("canvas");
  canvas.className = "cloud-canvas";
  try {
    renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
  } catch (e) {
    el.dataset.state = "message";
    const p = document.createElement("p");
    p.className = "cloud-view3d-message";
    p.textContent = `3D view: WebGL is not available in this browser (${e?.message || e})`;
    el.append(p);
    return { el, ok: false, message: p.textContent, show() {}, reset() {}, dispose() { el.remove(); } };
  }
  renderer.setPixelRatio(1);   // one drawn pixel per canvas pixel: what a test reads is what was drawn
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  renderer.setClearColor(BACKGROUND);
  canvas.style.height = `${height}px`;
  canvas.style.width = "100%";
  el.append(canvas);
  el.dataset.state = "ready";

  const scene = new THREE.Scene();
  const geometry = new THREE.BufferGeometry();
  const material = new THREE.PointsMaterial({ size: pointSize, sizeAttenuation: false, vertexColors: true });
  const points = new THREE.Points(geometry, material);
  points.frustumCulled = false;
  const grid = new THREE.GridHelper(2, 20, 0x9aa4b2, 0xd0d6de);
  grid.rotation.x = Math.PI / 2;   // x-y plane: z up
  const axes = new THREE.AxesHelper(0.2);
  scene.add(grid, axes, points);

  const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 1000);
  camera.up.set(0, 0, 1);
  camera.position.set(1.5, -2, 1.5);
  const controls = new OrbitControls(camera, canvas);
  controls.update();

  let frame = 0, renders = 0, disposed = false, fitted = false, bounds = null, drawnSize = { w: 0, h: 0 };
  const invalidate = () => { if (!frame && !disposed) frame = requestAnimationFrame(render); };
  controls.addEventListener("change", invalidate);

  function fit() {
    if (!bounds) return;
    const c = bounds.min.map((v, i) => (v + bounds.max[i]) / 2);
    const size = Math.max(1e-3, ...bounds.max.map((v, i) => v - bounds.min[i]));
    controls.target.set(c[0], c[1], c[2]);
    camera.position.set(c[0] + 0.9 * size, c[1] - 1.3 * size, c[2] + 0.9 * size);
    camera.near = size / 1000;
    camera.far = size * 100;
    camera.updateProjectionMatrix();
    const g = Math.max(1, Math.ceil(size * 2));
    grid.scale.set(g / 2, 1, g / 2);
    grid.position.set(c[0], c[1], bounds.min[2]);
    axes.scale.setScalar(Math.max(0.05, size / 5));
    controls.update();
    fitted = true;
  }

  function render() {
    frame = 0;
    if (disposed) return;
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

  const resize = new ResizeObserver(() => {
    if (canvas.clientWidth !== drawnSize.w || canvas.clientHeight !== drawnSize.h) invalidate();
  });
  resize.observe(canvas);
  invalidate();

  return {
    el,
    ok: true,
    message: null,
    show(drawn) {
      if (disposed || !drawn) return;
      const n = drawn.count;
      const pos = geometry.getAttribute("position"), col = geometry.getAttribute("color");
      if (pos && pos.count === n) {
        // same size: upload into the buffers there are
        pos.array.set(drawn.positions);
        col.array.set(drawn.colors);
        pos.needsUpdate = true;
        col.needsUpdate = true;
      } else {
        geometry.dispose();   // frees the GL buffers of the last size
        geometry.setAttribute("position", new THREE.BufferAttribute(drawn.positions, 3));
        geometry.setAttribute("color", new THREE.BufferAttribute(drawn.colors, 3, true));
      }
      geometry.setDrawRange(0, n);
      if (drawn.min) bounds = { min: drawn.min, max: drawn.max };
      if (!fitted) fit();
      el.dataset.points = String(n);
      invalidate();
    },
    reset() { fit(); invalidate(); },
    dispose() {
      if (disposed) return;
      disposed = true;
      if (frame) cancelAnimationFrame(frame);
      resize.disconnect();
      controls.dispose();
      geometry.dispose();
      material.dispose();
      grid.geometry.dispose(); grid.material.dispose();
      axes.geometry.dispose(); axes.material.dispose();
      renderer.dispose();
      renderer.forceContextLoss();
      el.remove();
    },
  };
}

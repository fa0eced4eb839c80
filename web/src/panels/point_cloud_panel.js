// The point cloud panel, for com.robotraconteur.pointcloud.sensor PointCloudSensor, PointCloud2Sensor and
// their Part variants: the newest cloud of the sensor's pipe drawn in 3D (three.js, loaded only when this
// panel opens; pointcloud/cloud_view3d.js), coloured by the cloud's own colour, its intensity or its
// height. Clouds are made drawable off the page's thread (std/pointcloud_decoder.js: newest wins, one
// being coloured, one waiting, never queued); parts are put back into whole clouds first. Beside it the
// sensor's info (bounds, resolution), the clouds received and drawn per second, the time each took, and
// for users allowed to call them: Capture (capture_point_cloud / capture_point_cloud2, drawn in the view
// in place of the live clouds until Live is pressed) and the parameter control. A device whose pipe is
// not of a standard cloud type gets one line.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { buildParamControl, parameterNames } from "./param_control.js";
import { RateMeter } from "./sensor_panel.js";
import { allows } from "../robot/access.js";
import { CloudAssembler, CLOUD_TYPES, CLOUD_PART_TYPES, boundsText, packCloud } from "../std/pointcloud.js";
import { CloudDecoder } from "../std/pointcloud_decoder.js";

const S = "com.robotraconteur.pointcloud.sensor";
/** The pipes, richest first: PointCloud2 (intensity, colour) before the positions-only one. */
const PIPES = ["point_cloud2_sensor_data", "point_cloud_sensor_data"];
const CAPTURES = { point_cloud2_sensor_data: "capture_point_cloud2", point_cloud_sensor_data: "capture_point_cloud" };
const ms = (x) => `${x < 10 ? x.toFixed(1) : Math.round(x)} ms`;
const MODE_LABELS = { auto: "auto", rgb: "colour (rgb)", intensity: "intensity", height: "height (z)" };

/** The cloud field's type of a sensor data pipe: { pipe, cloudType, part } or null when not standard. */
function pipeCloud(view, obj, pipe) {
  const t = pipe ? describeMember(view, obj, pipe)?.type : null;
  const f = t?.fields?.find((x) => x.name === "point_cloud")?.type;
  if (!f?.renderer) return null;
  if (CLOUD_TYPES.includes(f.qualified)) return { pipe, cloudType: f.qualified, part: false };
  if (CLOUD_PART_TYPES.includes(f.qualified)) return { pipe, cloudType: f.qualified, part: true };
  return null;
}

export function createPointCloudPanel(parent, ctx) {
  const { obj, view } = ctx;
  const members = obj.$members || [];
  const find = (name, kind) => members.find((m) => m.name === name && m.kind === kind) || null;
  let disposed = false;
  const cleanups = [];

  const errors = errorLine("cloud-error", () => !disposed);
  const info = h("dl", { class: "camera-info-rows cloud-info" });
  const status = h("output", { class: "cloud-status" });
  const controls = h("div", { class: "cloud-controls" });
  const viewBox = h("div", { class: "cloud-view" });
  const params = h("div", { class: "cloud-params" });
  const el = h("section", { class: "panel cloud-panel", dataset: { panel: "point-cloud", clouds: "0", received: "0" } },
    h("h3", { text: "Point cloud" }), info, errors.el, controls, status, viewBox, params);
  parent.append(el);
  const addRow = (label, text) => info.append(h("dt", { text: label }), h("dd", { text, dataset: { row: label } }));

  // point_sensor_info: read once
  let paramNames = [];
  const infoMember = find("point_sensor_info", "property");
  const infoRead = infoMember && !infoMember.writeonly && describeMember(view, obj, infoMember)?.type?.fields
    ? obj.point_sensor_info.get().then((v) => {
      if (disposed || !v) return;
      const b = boundsText(v.bounds);
      if (b) addRow("bounds", b);
      const r = v.resolution;
      if (r && [r.x, r.y, r.z].every((x) => typeof x === "number")) {
        addRow("resolution", r.x === r.y && r.y === r.z ? `${r.x} m` : `${r.x}, ${r.y}, ${r.z} m`);
      }
      paramNames = parameterNames(v.param_info);
      el.dataset.info = "read";
    }, (e) => errors.show(`point_sensor_info: ${errorText(e)}`))
    : Promise.resolve();

  const source = PIPES.map((n) => pipeCloud(view, obj, find(n, "pipe"))).find(Boolean) || null;
  if (!source || source.pipe.writeonly) {
    el.dataset.fallback = "true";
    el.append(h("div", { class: "hint cloud-fallback", text: "no point cloud pipe of a standard cloud type on this device: its members are shown below" }));
  } else {
    el.dataset.pipe = source.pipe.name;
    const received = new RateMeter(), drawnRate = new RateMeter();
    const assembler = source.part ? new CloudAssembler() : null;
    let paused = false, mode = "auto", nReceived = 0, nDrawn = 0, nCaptures = 0, last = null, view3d = null, pendingShow = null;
    const modeSelect = h("select", { class: "cloud-color", "aria-label": "colour points by" },
      ...Object.entries(MODE_LABELS).map(([v, t]) => h("option", { value: v, text: t })));
    const reset = h("button", { type: "button", class: "small", text: "Reset view", onclick: () => view3d?.reset() });
    controls.append(h("label", { class: "param" }, h("span", { text: "colour" }), modeSelect), reset);

    const decoder = new CloudDecoder({
      onResult: (r, meta) => {
        if (disposed) return;
        if (!r.ok) { errors.show(`${meta.what}: ${r.error.message}`); return; }
        nDrawn++;
        drawnRate.tick();
        last = { ...meta, points: r.count, ms: r.ms, packMs: r.packMs, mode: r.mode };
        el.dataset.clouds = String(nDrawn);
        el.dataset.points = String(r.count);
        el.dataset.colorMode = r.mode;
        el.dataset.decodeMs = String(r.ms);
        el.dataset.packMs = String(r.packMs);
        el.dataset.skipped = String(decoder.stats.dropped);
        if (meta.seqno !== undefined) el.dataset.seqno = String(meta.seqno);
        el.dataset.shown = meta.what;
        if (meta.capture) el.dataset.captures = String(++nCaptures);
        if (view3d) view3d.show(r); else pendingShow = r;
        writeStatus();
      },
    });
    cleanups.push(() => decoder.dispose());
    const writeStatus = () => {
      if (!last) return;
      const rate = (m) => (Math.round(m.rate() * 10) / 10).toString();
      status.textContent = `${last.points} points (${last.what}), coloured by ${last.mode}; ${rate(received)} clouds/s received, ${rate(drawnRate)} drawn`
        + `${decoder.stats.dropped ? `, ${decoder.stats.dropped} skipped for newer` : ""}${assembler?.dropped ? `, ${assembler.dropped} incomplete` : ""}`
        + `; copy ${ms(last.packMs)}, colour ${ms(last.ms)}${decoder.inWorker ? " (worker)" : ""}`
        + `${last.seqno !== undefined ? `; seqno ${last.seqno}` : ""}`;
    };
    modeSelect.addEventListener("change", () => { mode = modeSelect.value; });

    const follow = ctx.live.followPipe(source.pipe.name, {
      onPacket: (d) => {
        if (disposed) return;
        const seqno = d?.sensor_data?.data_header?.seqno;
        const meta = { what: source.pipe.name, seqno: seqno === undefined || seqno === null ? undefined : String(seqno) };
        const whole = assembler ? assembler.push(d?.point_cloud) : null;
        if (assembler && !whole) return;
        nReceived++;
        received.tick();
        el.dataset.received = String(nReceived);
        if (paused) return;   // a captured cloud is shown until Live
        decoder.submit(whole ? { packed: whole } : { cloud: d?.point_cloud }, { mode }, meta);
      },
      onOpen: (open) => { el.dataset.pipeOpen = open ? "true" : "false"; },
      onError: errors.onMemberError(source.pipe.name),
    });
    cleanups.push(() => follow.close());
    const tick = setInterval(writeStatus, 1000);
    cleanups.push(() => clearInterval(tick));

    // three.js only now: pages without a point cloud never fetch it
    import("../pointcloud/cloud_view3d.js").then(({ createCloudView3d }) => {
      if (disposed) return;
      view3d = createCloudView3d(viewBox);
      cleanups.push(() => view3d.dispose());
      if (pendingShow) { view3d.show(pendingShow); pendingShow = null; }
    }).catch((e) => { if (!disposed) viewBox.replaceChildren(h("p", { class: "cloud-view3d-message", text: `3D view: ${errorText(e)}` })); });

    // Capture: the sensor's capture function for the pipe shown (a generator for parts), drawn in the view
    const captureName = CAPTURES[source.pipe.name];
    const capture = find(captureName, "function");
    const addCapture = (access) => {
      if (!capture || !allows(access, captureName, "call")) return;
      const b = h("button", { type: "button", class: "small", text: "Capture", dataset: { action: captureName }, onclick: async () => {
        b.disabled = true;
        try {
          let packed;
          if (source.part) {
            const parts = new CloudAssembler();
            const gen = await obj[captureName]();
            for await (const p of gen) { packed = parts.push(p) || packed; if (disposed) return; }
            if (!packed) throw new Error("the parts did not make a whole cloud");
          } else {
            packed = packCloud(await obj[captureName]());
          }
          if (disposed) return;
          errors.show(null);
          paused = true;
          live.hidden = false;
          el.dataset.paused = "true";
          decoder.submit({ packed }, { mode }, { what: captureName, capture: true });
        } catch (e) {
          if (!disposed) errors.show(`${captureName}: ${errorText(e)}`);
        } finally {
          b.disabled = false;
        }
      } });
      const live = h("button", { type: "button", class: "small", text: "Live", hidden: true, dataset: { action: "live" }, onclick: () => {
        paused = false;
        live.hidden = true;
        el.dataset.paused = "false";
      } });
      controls.append(b, live);
    };
    whenAccess(ctx, el, infoRead, () => !disposed, (access) => {
      addCapture(access);
      buildParamControl(params, { obj, view, access, names: paramNames, onError: errors.show });
    }, errors.show);
    return { el, dispose() { disposed = true; for (const c of cleanups) c(); el.remove(); } };
  }

  whenAccess(ctx, el, infoRead, () => !disposed,
    (access) => buildParamControl(params, { obj, view, access, names: paramNames, onError: errors.show }), errors.show);
  return { el, dispose() { disposed = true; for (const c of cleanups) c(); el.remove(); } };
}

export const pointCloudPanel = {
  name: "point-cloud", order: 20,
  types: [`${S}.PointCloudSensor`, `${S}.PointCloud2Sensor`, `${S}.PointCloudPartSensor`, `${S}.PointCloud2PartSensor`],
  create: createPointCloudPanel,
};

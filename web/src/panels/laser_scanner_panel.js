// The laser scanner panel, for com.robotraconteur.laserscanner LaserScanner and LaserScanPartScanner:
// the newest scan of laser_scan_sensor_data drawn top-down (std/laserscan.js: the scanner at the
// centre facing up, rings every metre, intensities as colour; zoomed to the farthest return so far), at most once per animation frame,
// newest wins (scans arriving in between are counted as skipped, never queued); parts put back into
// whole scans first. Beside it the scanner's info (angle range and resolution, ranges, scan rate),
// the scans received per second, and the parameter control for users allowed to call
// getf_param / setf_param. A device whose pipe is not of a standard scan type gets a one-line note.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { drawScan, scanText, scanGeometry, ScanAssembler } from "../std/laserscan.js";
import { buildParamControl, parameterNames } from "./param_control.js";
import { RateMeter } from "./sensor_panel.js";
import { axisText } from "../sensor/sensor_source.js";

const LS = "com.robotraconteur.laserscanner";
const SCANS = ["com.robotraconteur.laserscan.LaserScan", "com.robotraconteur.laserscan.LaserScanf"];
const PARTS = ["com.robotraconteur.laserscan.LaserScanPart", "com.robotraconteur.laserscan.LaserScanPartf"];
const SIZE = 480;
const deg = (a) => `${axisText((a * 180) / Math.PI)}°`;

export function createLaserScannerPanel(parent, ctx) {
  const { obj, view } = ctx;
  const members = obj.$members || [];
  const find = (name, kind) => members.find((m) => m.name === name && m.kind === kind) || null;
  let disposed = false;
  const cleanups = [];

  const errors = errorLine("scan-error", () => !disposed);
  const error = errors.el, showError = errors.show;
  const info = h("dl", { class: "camera-info-rows scan-info" });
  const status = h("output", { class: "scan-status" });
  const canvas = h("canvas", { class: "scan-canvas", width: SIZE, height: SIZE, "aria-label": "laser scan, top view", style: "max-width: 100%; border: 1px solid #ddd" });
  const params = h("div", { class: "scan-params" });
  const el = h("section", { class: "panel scan-panel", dataset: { panel: "laser-scanner", scans: "0" } },
    h("h3", { text: "Laser scanner" }), info, error, status, h("div", { class: "scan-view" }, canvas), params);
  parent.append(el);
  const addRow = (label, text) => info.append(h("dt", { text: label }), h("dd", { text, dataset: { row: label } }));

  // scanner_info: read once
  let paramNames = [];
  const infoMember = find("scanner_info", "property");
  const infoRead = infoMember && !infoMember.writeonly && describeMember(view, obj, infoMember)?.type?.fields
    ? obj.scanner_info.get().then((v) => {
      if (disposed || !v) return;
      const g = v.scanner_info ? scanGeometry({ scan_info: v.scanner_info, ranges: { length: Number(v.scanner_info.angle_count) || 0 } }) : null;
      if (g) {
        addRow("angle range", `${deg(g.angleMin)} to ${deg(g.angleMax)}`);
        addRow("resolution", deg(g.angleIncrement));
        if (Number.isFinite(g.rangeMax)) addRow("range", `${axisText(g.rangeMin)} to ${axisText(g.rangeMax)} m`);
      }
      if (typeof v.scan_rate === "number" && v.scan_rate > 0) addRow("scan rate", `${axisText(v.scan_rate)} Hz`);
      paramNames = parameterNames(v.param_info);
      el.dataset.info = "read";
    }, (e) => showError(`scanner_info: ${errorText(e)}`))
    : Promise.resolve();

  const pipe = find("laser_scan_sensor_data", "pipe");
  const pipeType = pipe ? describeMember(view, obj, pipe)?.type : null;
  const whole = pipeType?.renderer && SCANS.includes(pipeType.qualified);
  const parts = pipeType?.renderer && PARTS.includes(pipeType.qualified);
  if (!whole && !parts) {
    el.dataset.fallback = "true";
    canvas.hidden = true;
    el.append(h("div", { class: "hint scan-fallback", text: "no laser_scan_sensor_data pipe of a standard scan type on this device: its members are shown below" }));
  } else {
    const g = canvas.getContext("2d");
    const meter = new RateMeter();
    const assembler = parts ? new ScanAssembler() : null;
    let newest = null, frame = 0, received = 0, drawn = 0, skipped = 0, reach = 0;
    const draw = () => {
      frame = 0;
      if (disposed || !newest) return;
      const scan = newest;
      newest = null;
      const r = drawScan(g, scan, SIZE, SIZE, { reach });
      reach = r.reach;  // zoom out when a return is farther, never back in: a steady picture
      drawn++;
      const seq = scan.scan_info?.data_header?.seqno;
      el.dataset.scans = String(drawn);
      el.dataset.points = String(r.points);
      el.dataset.scale = String(r.scale);
      status.textContent = `${scanText(scan)}; ${r.points} returns; ${axisText(Math.round(meter.rate() * 10) / 10)} scans/s`
        + `${skipped ? `, ${skipped} skipped for newer` : ""}${assembler?.dropped ? `, ${assembler.dropped} incomplete` : ""}`
        + `${seq !== undefined && seq !== null ? `; seqno ${seq}` : ""}`;
    };
    const take = (scan) => {
      received++;
      meter.tick();
      if (newest) skipped++;
      newest = scan;
      el.dataset.received = String(received);
      if (!frame) frame = requestAnimationFrame(draw);
    };
    const follow = ctx.live.followPipe(pipe.name, {
      onPacket: (p) => {
        if (disposed) return;
        if (assembler) { const s = assembler.push(p); if (s) take(s); } else take(p);
      },
      onOpen: (open) => { el.dataset.pipeOpen = open ? "true" : "false"; },
      onError: errors.onMemberError(pipe.name),
    });
    cleanups.push(() => { follow.close(); if (frame) cancelAnimationFrame(frame); });
  }

  whenAccess(ctx, el, infoRead, () => !disposed,
    (access) => buildParamControl(params, { obj, view, access, names: paramNames, onError: showError }), showError);

  return {
    el,
    dispose() {
      disposed = true;
      for (const c of cleanups) c();
      el.remove();
    },
  };
}

export const laserScannerPanel = {
  name: "laser-scanner", order: 20, types: [`${LS}.LaserScanner`, `${LS}.LaserScanPartScanner`], create: createLaserScannerPanel,
};

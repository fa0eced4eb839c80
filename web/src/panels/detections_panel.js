// The detections panel, for com.robotraconteur.fiducial.FiducialSensor and
// com.robotraconteur.objectrecognition.ObjectRecognitionSensor: the newest detections of the sensor's
// pipe as a table (what was seen, its class, its pose in the sensor's frame, the confidence), at most once
// per animation frame (newest wins); the sensor's info (range, resolution, the markers or object
// templates it knows); and for users allowed to call them Capture (capture_fiducials /
// capture_recognized_objects, shown in place of the live detections until Live) and the parameter
// control. A sensor whose pipe is not of the standard type gets one line and the generic view below.

import { h, errorText } from "../dom.js";
import { describeMember } from "../views/context.js";
import { errorLine, whenAccess } from "./panel_parts.js";
import { buildParamControl, parameterNames } from "./param_control.js";
import { allows } from "../robot/access.js";
import { formatPose } from "../std/geometry.js";
import { formatIdentifier } from "../std/identifier.js";
import { boundsText } from "../std/pointcloud.js";

/** What each sensor type's panel reads: its pipe, the list inside its packets, each item's fields. */
const KINDS = {
  "com.robotraconteur.fiducial.FiducialSensor": {
    title: "Fiducials", pipe: "fiducials_sensor_data", packetType: "com.robotraconteur.fiducial.FiducialSensorData",
    holder: "fiducials", list: "recognized_fiducials", capture: "capture_fiducials", info: "fiducial_sensor_info",
    id: (d) => d?.fiducial_marker || "", cls: (d) => formatIdentifier(d?.fiducial_marker_class) ?? "",
    known: (v) => (v?.fiducial_info || []).map((f) => f?.fiducial_marker_range ? `${formatIdentifier(f.fiducial_marker_class) ?? ""} ${f.fiducial_marker_range}`.trim() : formatIdentifier(f?.fiducial_marker_class)).filter(Boolean),
    knownLabel: "markers",
  },
  "com.robotraconteur.objectrecognition.ObjectRecognitionSensor": {
    title: "Recognised objects", pipe: "object_recognition_sensor_data", packetType: "com.robotraconteur.objectrecognition.ObjectRecognitionSensorData",
    holder: "recognized_objects", list: "recognized_objects", capture: "capture_recognized_objects", info: "object_recognition_sensor_info",
    id: (d) => formatIdentifier(d?.recognized_object) ?? "", cls: (d) => d?.recognized_object_class?.class_identifier ? formatIdentifier(d.recognized_object_class.class_identifier) ?? "" : "",
    known: (v) => (v?.object_template_identifiers || []).map(formatIdentifier).filter(Boolean),
    knownLabel: "templates",
  },
};

/** The table rows [{ id, cls, pose, confidence }] of a RecognizedFiducials / RecognizedObjects value. */
export function detectionRows(kind, holder) {
  const list = holder?.[kind.list];
  if (!Array.isArray(list)) return [];
  return list.filter(Boolean).map((d) => ({
    id: kind.id(d), cls: kind.cls(d),
    pose: formatPose(d?.pose?.pose?.pose) ?? "",
    frame: formatIdentifier(d?.pose?.pose?.parent_frame) ?? "",
    confidence: typeof d?.confidence === "number" && Number.isFinite(d.confidence) ? `${Math.round(d.confidence * 1000) / 10} %` : "",
  }));
}

export function createDetectionsPanel(parent, ctx) {
  const { obj, view } = ctx;
  const types = new Set([obj.$type, ...(obj.$implements || [])]);
  const kind = Object.entries(KINDS).find(([t]) => types.has(t))[1];
  const find = (name, k) => (obj.$members || []).find((m) => m.name === name && m.kind === k) || null;
  let disposed = false, frame = 0, newest = null, paused = false, count = 0, follow = null;

  const errors = errorLine("detections-error", () => !disposed);
  const info = h("dl", { class: "camera-info-rows detections-info" });
  const controls = h("div", { class: "camera-controls" });
  const status = h("output", { class: "detections-status" });
  const body = h("tbody");
  const table = h("table", { class: "param-info detections-table" },
    h("thead", {}, h("tr", {}, ...["id", "class", "pose", "frame", "confidence"].map((t) => h("th", { text: t })))), body);
  const params = h("div", { class: "detections-params" });
  const el = h("section", { class: "panel detections-panel", dataset: { panel: "detections", updates: "0" } },
    h("h3", { text: kind.title }), info, errors.el, controls, status, table, params);
  parent.append(el);
  const addRow = (label, text) => info.append(h("dt", { text: label }), h("dd", { text, dataset: { row: label } }));

  let paramNames = [];
  const infoMember = find(kind.info, "property");
  const infoRead = infoMember && !infoMember.writeonly
    ? obj[kind.info].get().then((v) => {
      if (disposed || !v) return;
      const range = boundsText(v.range);
      if (range) addRow("range", range);
      const r = v.resolution;
      if (r && [r.x, r.y, r.z].every((x) => typeof x === "number")) addRow("resolution", r.x === r.y && r.y === r.z ? `${r.x} m` : `${r.x}, ${r.y}, ${r.z} m`);
      const known = kind.known(v);
      if (known.length) addRow(kind.knownLabel, known.join(", "));
      paramNames = parameterNames(v.param_info);
      el.dataset.info = "read";
    }, (e) => errors.show(`${kind.info}: ${errorText(e)}`))
    : Promise.resolve();

  const show = (holder, what, seqno) => {
    const rows = detectionRows(kind, holder);
    body.replaceChildren(...rows.map((r) => h("tr", { dataset: { id: r.id } },
      h("td", { text: r.id }), h("td", { text: r.cls }), h("td", { text: r.pose }), h("td", { text: r.frame }), h("td", { text: r.confidence }))));
    el.dataset.detections = String(rows.length);
    el.dataset.shown = what;
    status.textContent = `${rows.length} detection${rows.length === 1 ? "" : "s"} (${what})${seqno !== undefined ? `; seqno ${seqno}` : ""}`;
  };

  const pipe = find(kind.pipe, "pipe");
  const pipeType = pipe && !pipe.writeonly ? describeMember(view, obj, pipe)?.type : null;
  const holderField = pipeType?.qualified === kind.packetType ? pipeType.fields?.find((f) => f.name === kind.holder) : null;
  if (!holderField?.type?.fields?.some((f) => f.name === kind.list)) {
    el.dataset.fallback = "true";
    table.hidden = true;
    el.append(h("div", { class: "hint detections-fallback", text: `no ${kind.pipe} pipe of the standard type on this device: its members are shown below` }));
  } else {
    const draw = () => {
      frame = 0;
      if (disposed || !newest || paused) return;
      const v = newest;
      newest = null;
      const seq = v?.sensor_data?.seqno;
      show(v?.[kind.holder], pipe.name, seq === undefined || seq === null ? undefined : String(seq));
      el.dataset.updates = String(++count);
    };
    follow = ctx.live.followPipe(pipe.name, {
      onPacket: (v) => { newest = v; if (!frame) frame = requestAnimationFrame(draw); },
      onOpen: (open) => { el.dataset.pipeOpen = open ? "true" : "false"; },
      onError: errors.onMemberError(pipe.name),
    });
  }

  whenAccess(ctx, el, infoRead, () => !disposed, (access) => {
    if (find(kind.capture, "function") && allows(access, kind.capture, "call")) {
      const live = h("button", { type: "button", class: "small", text: "Live", hidden: true, dataset: { action: "live" }, onclick: () => {
        paused = false;
        live.hidden = true;
      } });
      const b = h("button", { type: "button", class: "small", text: "Capture", dataset: { action: kind.capture }, onclick: async () => {
        b.disabled = true;
        try {
          const r = await obj[kind.capture]();
          if (disposed) return;
          paused = true;
          live.hidden = false;
          errors.show(null);
          show(r, kind.capture);
        } catch (e) {
          if (!disposed) errors.show(`${kind.capture}: ${errorText(e)}`);
        } finally {
          b.disabled = false;
        }
      } });
      controls.append(b, live);
    }
    buildParamControl(params, { obj, view, access, names: paramNames, onError: errors.show });
  }, errors.show);

  return {
    el,
    dispose() { disposed = true; follow?.close(); if (frame) cancelAnimationFrame(frame); el.remove(); },
  };
}

export const detectionsPanel = { name: "detections", order: 20, types: Object.keys(KINDS), create: createDetectionsPanel };

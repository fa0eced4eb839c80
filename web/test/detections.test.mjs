// The detections and image-part panels' pure parts without a browser: a RecognizedFiducials and a
// RecognizedObjects value as table rows (identifier, class, pose, frame, confidence), and ImageParts
// joined into one Image (in order, or refused with what is wrong).
import { test } from "node:test";
import assert from "node:assert/strict";
import { detectionRows, detectionsPanel } from "../src/panels/detections_panel.js";
import { joinImageParts } from "../src/panels/image_part_camera_panel.js";

const ident = (name) => ({ name, uuid: { uuid_bytes: new Uint8Array(16) } });
const pose = (x, y, z, yawDeg) => {
  const h = (yawDeg * Math.PI) / 360;
  return { pose: { parent_frame: ident("camera_link"), frame: ident(""), pose: { orientation: { w: Math.cos(h), x: 0, y: 0, z: Math.sin(h) }, position: { x, y, z } } }, covariance: null };
};
const kind = (t) => detectionsPanel.types.includes(t);

test("detectionRows: fiducials and objects as rows of id, class, pose, frame, confidence", () => {
  assert.ok(kind("com.robotraconteur.fiducial.FiducialSensor") && kind("com.robotraconteur.objectrecognition.ObjectRecognitionSensor"));
  const fid = { recognized_fiducials: [
    { fiducial_marker_class: ident("aruco_4x4_50"), fiducial_marker: "aruco_4x4:7", pose: pose(0.4, 0.1, 1.2, 90), confidence: 0.98 },
    null,
  ] };
  const fk = { list: "recognized_fiducials", id: (d) => d.fiducial_marker, cls: (d) => d.fiducial_marker_class.name };
  assert.deepEqual(detectionRows(fk, fid), [
    { id: "aruco_4x4:7", cls: "aruco_4x4_50", pose: "position (0.4, 0.1, 1.2) m, rpy (0, 0, 90)°", frame: "camera_link", confidence: "98 %" },
  ]);
  const ok = { list: "recognized_objects", id: (d) => d.recognized_object.name, cls: (d) => d.recognized_object_class.class_identifier.name };
  const objs = { recognized_objects: [{ recognized_object: ident("mug"), recognized_object_class: { class_identifier: ident("cup") }, pose: pose(0.3, -0.1, 0.75, 0), confidence: Number.NaN }] };
  assert.deepEqual(detectionRows(ok, objs), [{ id: "mug", cls: "cup", pose: "position (0.3, -0.1, 0.75) m, rpy (0, 0, 0)°", frame: "camera_link", confidence: "" }]);
  assert.deepEqual(detectionRows(ok, { recognized_objects: null }), []);
  assert.deepEqual(detectionRows(ok, null), []);
});

test("joinImageParts: parts in order make the Image; gaps, overlaps and bad sizes refused", () => {
  const info = { width: 2, height: 1, step: 6, encoding: 0x1000 };
  const part = (o, t, bytes) => ({ image_info: info, data_offset: o, data_total_len: t, data_part: Uint8Array.from(bytes) });
  const img = joinImageParts([part(0, 6, [1, 2, 3]), part(3, 6, [4, 5]), part(5, 6, [6])]);
  assert.equal(img.image_info, info);
  assert.deepEqual(Array.from(img.data), [1, 2, 3, 4, 5, 6]);
  assert.throws(() => joinImageParts([part(3, 6, [4, 5, 6])]), /first part starts at 3/);
  assert.throws(() => joinImageParts([part(0, 6, [1, 2]), part(3, 6, [4, 5, 6])]), /part at 3 of 6 after 2 of 6/);
  assert.throws(() => joinImageParts([part(0, 6, [1, 2, 3])]), /3 of 6 bytes came/);
  assert.throws(() => joinImageParts([part(0, 2, [1, 2, 3])]), /does not fit/);
  assert.throws(() => joinImageParts([]), /no parts/);
});

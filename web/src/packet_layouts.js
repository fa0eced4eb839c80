// Byte layouts that a device documents inside an opaque field, decoded for plotting. One entry per
// qualified struct type: a function from the value to [[seriesName, number], ...].

/**
 * experimental.create.SensorPacket (the demo Create, server/demo/create_device.hpp): ID 19 and Data,
 * little-endian: u8 version, u8 bumpers, u16 sequence, i32 DistanceTraveled (mm), i32 AngleTraveled
 * (degrees), i32 x (mm), i32 y (mm), i32 heading (0.01 degree), i16 velocity (mm/s), i16 radius (mm),
 * u32 time (ms), u16 wall hits, u8 song length, u8 song first byte.
 */
function createSensorPacket(v) {
  const data = v && v.Data;
  if (!ArrayBuffer.isView(data) || data.length < 36 || data[0] !== 1) return null;
  const d = new DataView(data.buffer, data.byteOffset, data.byteLength);
  return [
    ["DistanceTraveled", d.getInt32(4, true)], ["AngleTraveled", d.getInt32(8, true)],
    ["x", d.getInt32(12, true)], ["y", d.getInt32(16, true)],
    ["heading", d.getInt32(20, true) / 100, true], ["velocity", d.getInt16(24, true), true],
    ["radius", d.getInt16(26, true), true], ["bumpers", d.getUint8(1), true],
    ["wall_hits", d.getUint16(32, true), true], ["seq", d.getUint16(2, true), true],
    ["time", d.getUint32(28, true) / 1000, true], ["song_length", d.getUint8(34), true],
    ["song_first", d.getUint8(35), true],
  ];
}

const LAYOUTS = { "experimental.create.SensorPacket": createSensorPacket };

/** Decoded series ([name, number, hiddenAtFirst]), or null when the type has no known layout (or the bytes do not match it). */
export function decodeKnown(qualifiedType, value) {
  const f = LAYOUTS[qualifiedType];
  return f ? f(value) : null;
}

// The clock panel's pure logic (panels/clock_panel.js): com.robotraconteur.datetime.clock values, and the
// device's time against the browser's clock.

import { timeSeconds, isoTime, timeParts } from "../std/datetime.js";

/** A pod value as the client gives it (an array of one), or the value itself. */
export const onePod = (v) => (Array.isArray(v) && v.length === 1 ? v[0] : v);

/**
 * How far the device's time `v` (DateTimeUTC) is ahead of the browser's clock, in seconds, given
 * `receivedMs` (Date.now() when the value arrived): positive when the device is ahead. Null for a value
 * that is no time. Transport delay counts against the device (its time is older when it arrives).
 */
export function clockOffset(v, receivedMs) {
  const s = timeSeconds(onePod(v));
  return s === null ? null : s - receivedMs / 1000;
}

/** "+1.250 s", "-12 ms": an offset in seconds as short signed text (milliseconds below one second). */
export function offsetText(seconds) {
  if (seconds === null || !Number.isFinite(seconds)) return "";
  const sign = seconds < 0 ? "-" : "+";
  const a = Math.abs(seconds);
  return a < 1 ? `${sign}${Math.round(a * 1000)} ms` : `${sign}${a.toFixed(3)} s`;
}

/** ISO text of a DateTimeUTC (UTC) or DateTimeLocal (its own offset and zone name). */
export function clockText(v) {
  const t = onePod(v);
  const parts = timeParts(t);
  if (!parts) return "";
  const iso = isoTime(parts, t.utc_offset_seconds ?? 0) ?? "";
  return t.timezone_name ? `${iso} ${t.timezone_name}` : iso;
}

/** "+02:00 (Europe/Berlin)" of a ClockDeviceInfo's time zone. */
export function zoneText(info) {
  if (!info) return "";
  const s = Number(info.timezone_utc_offset_seconds ?? 0);
  const a = Math.abs(s);
  const hhmm = `${s < 0 ? "-" : "+"}${String(Math.floor(a / 3600)).padStart(2, "0")}:${String(Math.floor((a % 3600) / 60)).padStart(2, "0")}`;
  return info.timezone_name ? `${hhmm} (${info.timezone_name})` : hhmm;
}

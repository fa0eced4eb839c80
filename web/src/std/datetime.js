// Times of com.robotraconteur.datetime as ISO 8601 text plus their age: DateTimeUTC, TimeSpec2 (pods:
// ClockInfo clock_info, int64 seconds, int32 nanoseconds), DateTimeLocal (struct: the same and int32
// utc_offset_seconds, string timezone_name), TimeSpec3 (namedarray: int64 microseconds), Duration.
// Seconds count from 1970-01-01T00:00:00Z (the definition's EPOCH_ISO8601). TimeSpec2 and TimeSpec3
// are on the sending node's clock, which RR keeps close to real time (not synchronised between nodes).

const NS = 1000000000n;

/**
 * { seconds: BigInt, nanoseconds: 0..999999999 } of a time value: {seconds, nanoseconds} (BigInt or
 * number seconds) or {microseconds} (TimeSpec3). Null for anything else.
 */
export function timeParts(v) {
  if (!v || typeof v !== "object") return null;
  try {
    let total;
    if ("microseconds" in v && !("seconds" in v)) total = BigInt(v.microseconds) * 1000n;
    else if ("seconds" in v) total = BigInt(v.seconds) * NS + BigInt(Math.trunc(Number(v.nanoseconds) || 0));
    else return null;
    let seconds = total / NS, nanoseconds = total % NS;
    if (nanoseconds < 0n) { nanoseconds += NS; seconds -= 1n; }
    return { seconds, nanoseconds: Number(nanoseconds) };
  } catch {
    return null;  // not integers
  }
}

/** Seconds since the epoch as a number (fractions in it; microseconds kept for today's dates), or null. */
export function timeSeconds(v) {
  const p = timeParts(v);
  return p ? Number(p.seconds) + p.nanoseconds / 1e9 : null;
}

/**
 * ISO 8601 text of `parts` (timeParts): "2024-05-01T12:00:00.25Z", the fraction as written (up to 9
 * digits, none when zero); with `offsetSeconds` the local time and "+02:00". Null outside the years
 * Date can hold.
 */
export function isoTime(parts, offsetSeconds = 0) {
  if (!parts) return null;
  const local = Number(parts.seconds) + Number(offsetSeconds || 0);
  if (!Number.isFinite(local) || Math.abs(local) > 8.64e12) return null;
  const base = new Date(local * 1000).toISOString().slice(0, 19);
  const fraction = parts.nanoseconds ? `.${String(parts.nanoseconds).padStart(9, "0").replace(/0+$/, "")}` : "";
  return `${base}${fraction}${offsetText(offsetSeconds)}`;
}

function offsetText(offset) {
  const s = Number(offset || 0);
  if (!s) return "Z";
  const a = Math.abs(s);
  const hhmm = `${String(Math.floor(a / 3600)).padStart(2, "0")}:${String(Math.floor((a % 3600) / 60)).padStart(2, "0")}`;
  return `${s < 0 ? "-" : "+"}${hhmm}`;
}

/** A duration in seconds as short text: "250 ms", "3.2 s", "4.5 min", "2.0 h", "3.1 d". */
export function durationText(seconds) {
  const a = Math.abs(seconds);
  const sign = seconds < 0 ? "-" : "";
  if (a < 1) return `${sign}${Math.round(a * 1000)} ms`;
  if (a < 60) return `${sign}${a.toFixed(1)} s`;
  if (a < 3600) return `${sign}${(a / 60).toFixed(1)} min`;
  if (a < 86400) return `${sign}${(a / 3600).toFixed(1)} h`;
  return `${sign}${(a / 86400).toFixed(1)} d`;
}

/** "3.2 s ago" for a time `ageSeconds` in the past, "in 1.0 s" for one ahead of the page's clock
 * (less than half a millisecond ahead is "0 ms ago"). */
export function ageText(ageSeconds) {
  return ageSeconds > -0.0005 ? `${durationText(Math.max(ageSeconds, 0))} ago` : `in ${durationText(-ageSeconds)}`;
}

/**
 * Whether a time of clock type `clockType` (ClockInfo.clock_type) can be compared with the page's
 * clock: not for simulation, arbitrary, TAI and auxiliary clocks (named by `clockEnum`, the device's
 * ClockTypeCode values); yes when the enum is not known.
 */
export function comparableClock(clockType, clockEnum) {
  const name = clockEnum?.find((e) => e.value === Number(clockType))?.name;
  return !name || !/^(sim_|aux_)|_(arb|tai)_clock$/.test(name);
}

/**
 * Text of a time value: "2024-05-01T12:00:00.25Z (3.2 s ago)"; "(not set)" for zero; the clock's name
 * instead of the age when the clock is not comparable; null for a value that is not a time.
 * @param {object} v  a DateTimeUTC, TimeSpec2, TimeSpec3 or DateTimeLocal value
 * @param {{now?: number, clockEnum?: Array<{name, value}>}} [ctx]  now: the page's time in ms since the epoch
 */
export function formatTime(v, ctx = {}) {
  const parts = timeParts(v);
  if (!parts) return null;
  if (parts.seconds === 0n && parts.nanoseconds === 0) return "(not set)";
  const iso = isoTime(parts, v.utc_offset_seconds) ?? `${parts.seconds} s ${parts.nanoseconds} ns`;
  const zone = v.timezone_name ? ` ${v.timezone_name}` : "";
  const clockType = v.clock_info?.clock_type;
  if (clockType !== undefined && !comparableClock(clockType, ctx.clockEnum)) {
    const name = ctx.clockEnum?.find((e) => e.value === Number(clockType))?.name;
    return `${iso}${zone} (${name} clock)`;
  }
  const now = ctx.now ?? Date.now();
  return `${iso}${zone} (${ageText(now / 1000 - (Number(parts.seconds) + parts.nanoseconds / 1e9))})`;
}

/** Text of a Duration value ("1.5 s"), or null. */
export function formatDuration(v) {
  const p = timeParts(v);
  return p ? durationText(Number(p.seconds) + p.nanoseconds / 1e9) : null;
}

const CLOCK_ENUM = "com.robotraconteur.datetime.ClockTypeCode";
const withClocks = (ctx) => ({ ...ctx, clockEnum: ctx?.clockEnum ?? ctx?.outline?.types?.get(CLOCK_ENUM)?.values });
const timeText = (v, ctx) => formatTime(v, withClocks(ctx)) ?? "(not a time)";
const SECONDS = { seconds: "int64", nanoseconds: "int32" };

export const renderers = [
  { type: "com.robotraconteur.datetime.DateTimeUTC", layout: SECONDS, text: timeText },
  { type: "com.robotraconteur.datetime.TimeSpec2", layout: SECONDS, text: timeText },
  { type: "com.robotraconteur.datetime.TimeSpec3", layout: { microseconds: "int64" }, text: timeText },
  {
    type: "com.robotraconteur.datetime.DateTimeLocal",
    layout: { ...SECONDS, utc_offset_seconds: "int32", timezone_name: "string" },
    text: timeText,
  },
  { type: "com.robotraconteur.datetime.Duration", layout: SECONDS, text: (v) => formatDuration(v) ?? "(not a duration)" },
];

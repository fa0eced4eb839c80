// The event log panel's pure logic (panels/event_log_panel.js): com.robotraconteur.eventlog messages as
// table rows, the filter a person types, and the bounded window of messages kept.

import { enumName } from "../std/enums.js";
import { timeParts, isoTime } from "../std/datetime.js";

/** Messages read at most per request (getf_eventlog_messages count) and kept in the table. */
export const READ_COUNT = 200;
export const KEEP = 1000;

/** A table row { number (BigInt), time, level, levelValue, source, title, message } of an EventLogMessage. */
export function messageRow(m, levelEnum) {
  const hdr = m?.header ?? {};
  const parts = timeParts(Array.isArray(hdr.timestamp) ? hdr.timestamp[0] : hdr.timestamp);
  const source = [hdr.source_device?.name, hdr.source_component, hdr.source_object].filter(Boolean).join(" / ");
  let number;
  try { number = BigInt(hdr.message_number ?? 0); } catch { number = 0n; }
  return {
    number,
    time: parts ? isoTime(parts) ?? "" : "",
    level: enumName(levelEnum, hdr.level) ?? String(hdr.level ?? ""),
    levelValue: Number(hdr.level ?? 0),
    source,
    title: String(m?.title ?? ""),
    message: String(m?.message ?? ""),
  };
}

/**
 * True when `row` passes the filter: its level at least `minLevel` (a number, 0: all) and every word of
 * `text` found (case-insensitive) in its level, source, title or message.
 */
export function passes(row, text, minLevel = 0) {
  if (row.levelValue < minLevel) return false;
  const hay = `${row.level} ${row.source} ${row.title} ${row.message}`.toLowerCase();
  return String(text ?? "").toLowerCase().split(/\s+/).filter(Boolean).every((w) => hay.includes(w));
}

/** Rows merged by message number (a number seen before is replaced), newest first, at most `keep`. */
export function mergeRows(rows, incoming, keep = KEEP) {
  const byNumber = new Map(rows.map((r) => [r.number, r]));
  for (const r of incoming) byNumber.set(r.number, r);
  return [...byNumber.values()].sort((a, b) => (a.number < b.number ? 1 : a.number > b.number ? -1 : 0)).slice(0, keep);
}

/** The start and count of the newest READ_COUNT messages of an EventLogInfo ({min,max}_message_number). */
export function newestWindow(info, count = READ_COUNT) {
  let min, max;
  try { min = BigInt(info?.min_message_number ?? 0); max = BigInt(info?.max_message_number ?? 0); } catch { return null; }
  if (max < min) return null;
  const n = max - min + 1n;
  const c = n < BigInt(count) ? n : BigInt(count);
  return { start: max - c + 1n, count: c };
}

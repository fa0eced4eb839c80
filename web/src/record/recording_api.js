// The gateway's recording and replay routes (docs/recording.md "JSON API" and "Replay"), called with
// relative URLs like every request of the page, so that a path prefix and the login cookie work as
// they do for api/devices. Pure helpers (the request body, number formats) are exported for tests.

/** Members a recording can take (docs/recording.md "Recording in the gateway"); functions are not. */
export const RECORDABLE_KINDS = Object.freeze(["wire", "pipe", "event", "property"]);
/** Kinds checked by default: what the gateway records when no members are named. */
export const DEFAULT_KINDS = Object.freeze(["wire", "pipe", "event"]);
/** The encodings offered: one of them or both (the `encoding` key of a `record:` entry). */
export const ENCODINGS = Object.freeze({ both: ["json", "robotraconteur"], json: ["json"], robotraconteur: ["robotraconteur"] });

/** The members of a device proxy ($members: [{name, kind}]) that can be recorded, in definition order. */
export function recordableMembers(members) {
  return (members || []).filter((m) => RECORDABLE_KINDS.includes(m.kind)).map((m) => ({ name: m.name, kind: m.kind }));
}

/**
 * Members below the root object typed by the user (docs/recording.md "Objects below the root"):
 * object path, `.`, member, e.g. `Webcams[0].FrameStream`; separated by commas, spaces or new lines
 * outside brackets (a string key in brackets may hold them). Empty entries are dropped; the gateway
 * checks each name (400 with the reason).
 * @param {string} text
 * @returns {string[]}
 */
export function parseMemberPaths(text) {
  const out = [];
  let cur = "", depth = 0;
  for (const c of String(text ?? "")) {
    if (c === "[") depth++;
    else if (c === "]" && depth > 0) depth--;
    if (depth === 0 && /[\s,]/.test(c)) {
      if (cur) out.push(cur);
      cur = "";
    } else {
      cur += c;
    }
  }
  if (cur) out.push(cur);
  return out;
}

/**
 * The body of POST api/recordings: { device, members, encoding[, directory] }.
 * Throws Error when no member is chosen or the encoding is not a key of ENCODINGS.
 */
export function recordingBody({ device, members, encoding = "both", directory = "" }) {
  if (!members?.length) throw new Error("choose at least one member to record");
  const enc = ENCODINGS[encoding];
  if (!enc) throw new Error(`unknown encoding "${encoding}"`);
  const body = { device, members: [...members], encoding: [...enc] };
  if (directory && directory.trim()) body.directory = directory.trim();
  return body;
}

/** Bytes as text for people: "0 B", "512 B", "1.5 KiB", "12.3 MiB", "2.00 GiB". */
export function formatBytes(n) {
  if (!Number.isFinite(n) || n < 0) return "–";
  const units = ["B", "KiB", "MiB", "GiB", "TiB"];
  let i = 0;
  while (n >= 1024 && i < units.length - 1) { n /= 1024; i++; }
  if (i === 0) return `${n} B`;
  return `${n.toFixed(n < 10 ? 2 : 1)} ${units[i]}`;
}

/** Seconds as "m:ss.s" (or "h:mm:ss.s" from an hour on); "–" for a missing value. */
export function formatSeconds(s) {
  if (!Number.isFinite(s)) return "–";
  const neg = s < 0;
  s = Math.abs(s);
  const h = Math.floor(s / 3600);
  const m = Math.floor((s % 3600) / 60);
  const sec = (s % 60).toFixed(1).padStart(4, "0");
  const body = h ? `${h}:${String(m).padStart(2, "0")}:${sec}` : `${m}:${sec}`;
  return neg ? `-${body}` : body;
}

/** A replay file's time span from its start (ns since the Unix epoch, a number or a string) and duration: ISO texts. */
export function timeSpan(startNs, durationS) {
  const startMs = Number(BigInt(String(startNs ?? 0)) / 1000000n);
  if (!Number.isFinite(startMs) || !Number.isFinite(durationS)) return null;
  return { start: new Date(startMs).toISOString(), end: new Date(startMs + durationS * 1000).toISOString() };
}

/** The recordings of one device from a GET api/recordings answer, newest (highest id) first. */
export function recordingsOf(answer, device) {
  const list = Array.isArray(answer?.recordings) ? answer.recordings : [];
  return list.filter((r) => r.device === device).sort((a, b) => b.id - a.id);
}

/** The body of POST api/replays/{name}: only the keys given, in the gateway's order (position, speed, loop, state). */
export function replayControlBody({ position_s, speed, loop, state } = {}) {
  const body = {};
  if (position_s !== undefined) {
    if (!Number.isFinite(position_s) || position_s < 0) throw new Error(`bad position ${position_s}`);
    body.position_s = position_s;
  }
  if (speed !== undefined) {
    if (!Number.isFinite(speed) || speed <= 0) throw new Error(`bad speed ${speed}`);
    body.speed = speed;
  }
  if (loop !== undefined) body.loop = !!loop;
  if (state !== undefined) {
    if (state !== "playing" && state !== "paused") throw new Error(`bad state ${state}`);
    body.state = state;
  }
  return body;
}

/** Error thrown for a refused request: `status` the HTTP status, message the gateway's. */
export class ApiRequestError extends Error {
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

/**
 * One JSON request to the gateway; resolves with the parsed answer. A refusal throws ApiRequestError
 * with the gateway's `error.message` (e.g. the recorder's "record: … Permission denied"), a network
 * failure the fetch error. `fetchImpl` is replaceable for tests.
 */
export async function apiRequest(method, url, body = undefined, fetchImpl = globalThis.fetch) {
  const init = { method, headers: { Accept: "application/json" }, cache: "no-store" };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  const r = await fetchImpl(url, init);
  let data = null;
  try { data = await r.json(); } catch { /* no JSON body */ }
  if (!r.ok) throw new ApiRequestError(r.status, data?.error?.message || `${method} ${url}: HTTP ${r.status}`);
  return data;
}

export const listRecordings = (f) => apiRequest("GET", "api/recordings", undefined, f);
export const startRecording = (body, f) => apiRequest("POST", "api/recordings", body, f);
export const stopRecording = (id, f) => apiRequest("POST", `api/recordings/${encodeURIComponent(id)}/stop`, {}, f);
export const listReplays = (f) => apiRequest("GET", "api/replays", undefined, f);
export const replayStatus = (name, f) => apiRequest("GET", `api/replays/${encodeURIComponent(name)}`, undefined, f);
export const controlReplay = (name, body, f) => apiRequest("POST", `api/replays/${encodeURIComponent(name)}`, replayControlBody(body), f);

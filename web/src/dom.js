// Small DOM helpers: every text goes in through textContent, never as HTML.

/**
 * Creates an element. `attrs`: attributes, except `class`, `text`, `on<event>` (listeners) and
 * `dataset` (an object). Children: nodes, strings or null (skipped).
 */
export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === "class") el.className = v;
    else if (k === "text") el.textContent = v;
    else if (k === "dataset") Object.assign(el.dataset, v);
    else if (k.startsWith("on") && typeof v === "function") el.addEventListener(k.slice(2), v);
    else if (v === true) el.setAttribute(k, "");
    else el.setAttribute(k, String(v));
  }
  for (const c of children.flat()) {
    if (c === null || c === undefined || c === false) continue;
    el.append(c instanceof Node ? c : String(c));
  }
  return el;
}

/** The text of an error for the page: RRError's errorName and message, else the JS message. */
export function errorText(err) {
  if (err && typeof err === "object" && "errorName" in err) return `${err.errorName}: ${err.message}`;
  if (err instanceof Error) return err.message;
  return String(err);
}

/** A clock time with milliseconds, for logs. */
export function clockText(date = new Date()) {
  return date.toLocaleTimeString([], { hour12: false }) + "." + String(date.getMilliseconds()).padStart(3, "0");
}

// "Open in Foxglove / Lichtblick" on a device page (docs/foxglove.md): the gateway's Foxglove WebSocket
// URL for this page's origin and folder, a link that opens it in Foxglove's web app, and a button that
// copies it for Lichtblick (its "Open connection" → "Foxglove WebSocket" dialog, or a Lichtblick web
// app's own `?ds=foxglove-websocket&ds.url=` link). Every device of the gateway is on the one URL; the
// device's channels are the topics under `<device>/`.

import { h } from "./dom.js";

/** ws[s]://host/<folder>/foxglove for the page at `loc`. */
export function foxgloveUrl(loc = window.location) {
  const scheme = loc.protocol === "https:" ? "wss" : "ws";
  const folder = new URL(".", `${loc.protocol}//${loc.host}${loc.pathname}`).pathname;
  return `${scheme}://${loc.host}${folder}foxglove`;
}

/** Foxglove's web app opening `url` as a Foxglove WebSocket connection. */
export function foxgloveAppLink(url) {
  return `https://app.foxglove.dev/~/view?ds=foxglove-websocket&ds.url=${encodeURIComponent(url)}`;
}

/** The links for device `name`'s page. */
export function foxgloveLinks(name, loc = window.location) {
  const url = foxgloveUrl(loc);
  const copy = h("button", { type: "button", class: "small foxglove-copy", text: "Copy URL for Lichtblick",
    title: `Lichtblick: Open connection → Foxglove WebSocket → ${url} (topics ${name}/…)`,
    onclick: () => navigator.clipboard?.writeText(url).then(() => { copy.textContent = "Copied"; }, () => {}) });
  return h("span", { class: "foxglove-links", dataset: { url } },
    h("a", { href: foxgloveAppLink(url), target: "_blank", rel: "noopener", text: "Open in Foxglove",
      title: `Foxglove WebSocket ${url} (topics ${name}/…)` }),
    copy);
}

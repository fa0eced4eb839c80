// What the Lichtblick tests share (test/foxglove/lichtblick_live_test.mjs, test/record/lichtblick_open_test.mjs):
// the built app found or the test skipped, a static server for it with a default layout, the gateway's
// JSON API, and the pixels of a panel's screenshot.
import assert from "node:assert/strict";
import fs from "node:fs";
import http from "node:http";
import path from "node:path";

/** LICHTBLICK_WEB (a built Lichtblick web app, scripts/build-lichtblick.sh), or exit 77 with the reason. */
export function lichtblickWebOrSkip() {
  const web = process.env.LICHTBLICK_WEB;
  if (!web || !fs.existsSync(path.join(web, "index.html"))) {
    console.log(`SKIP: LICHTBLICK_WEB ${web ? `(${web}) has no index.html` : "is not set"}: build the app with scripts/build-lichtblick.sh`);
    process.exit(77);
  }
  return web;
}

const TYPES = { ".js": "text/javascript", ".wasm": "application/wasm", ".html": "text/html", ".css": "text/css",
  ".json": "application/json", ".png": "image/png", ".svg": "image/svg+xml", ".woff2": "font/woff2", ".ico": "image/x-icon" };

/**
 * Serves the app at `web` on 127.0.0.1 (a free port), its index.html opening with `layout` (Lichtblick's
 * LayoutData, through its default-layout placeholder). `route(req, res, url)` may answer a request first
 * (returns true when it did). Resolves to the http.Server.
 */
export function serveLichtblick(web, layout, route = () => false) {
  const index = fs.readFileSync(path.join(web, "index.html"), "utf8");
  assert.ok(index.includes("/*LICHTBLICK_SUITE_DEFAULT_LAYOUT_PLACEHOLDER*/"), "the app's index.html has the default-layout placeholder");
  const indexWithLayout = index.replace("/*LICHTBLICK_SUITE_DEFAULT_LAYOUT_PLACEHOLDER*/", JSON.stringify(layout));
  const srv = http.createServer((req, res) => {
    const url = new URL(req.url, "http://x");
    if (route(req, res, url)) return;
    const rel = url.pathname === "/" ? "index.html" : path.normalize(decodeURIComponent(url.pathname)).replace(/^\/+/, "");
    if (rel === "index.html") {
      res.writeHead(200, { "Content-Type": "text/html" });
      return res.end(indexWithLayout);
    }
    const p = path.join(web, rel);
    if (!p.startsWith(web) || !fs.existsSync(p) || !fs.statSync(p).isFile()) { res.writeHead(404); return res.end(); }
    res.writeHead(200, { "Content-Type": TYPES[path.extname(p)] || "application/octet-stream" });
    fs.createReadStream(p).pipe(res);
  });
  return new Promise((resolve) => srv.listen(0, "127.0.0.1", () => resolve(srv)));
}

/** One JSON API request to the gateway at `base`: { status, body (parsed, or null when empty) }. */
export async function gatewayApi(base, method, p, body) {
  const r = await fetch(`${base}${p}`, { method, headers: { "content-type": "application/json" }, body: body && JSON.stringify(body) });
  const text = await r.text();
  return { status: r.status, body: text ? JSON.parse(text) : null };
}

/** The RGBA pixels of `locator`'s screenshot, decoded by `page` itself: { width, height, data }. */
export async function shotPixels(page, locator) {
  const png = await locator.screenshot();
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement("canvas");
    c.width = img.width; c.height = img.height;
    const g = c.getContext("2d");
    g.drawImage(img, 0, 0);
    return { width: c.width, height: c.height, data: Array.from(g.getImageData(0, 0, c.width, c.height).data) };
  }, png.toString("base64"));
}

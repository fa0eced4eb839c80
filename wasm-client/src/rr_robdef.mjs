#!/usr/bin/env node
// `rr-robdef` as the package ships it (package.json "bin"): the project's rr-robdef compiled to
// WebAssembly (rr_robdef_node.cjs/.wasm, the same tool as the native one), plus the definitions' sources a
// TypeScript developer has at hand (README.md "TypeScript quickstart"):
//
//   rr-robdef ts [-o DIR] [--dts] --url rr+ws://HOST:PORT/?service=NAME     the running service's definitions
//   rr-robdef ts [-o DIR] [--dts] --gateway http://HOST:PORT --device NAME  a gateway device's (JSON API)
//   rr-robdef ts [-o DIR] [--dts] --definitions FILE|-                      the JSON API's {"definitions": [...]}
//   rr-robdef ts|check|format ...                                            as the native rr-robdef (files)
//
// The fetched definitions are written as <service>.robdef into a temporary folder and handed to the tool,
// which writes one module per definition (imports included). Exit status: the tool's; 1 when the
// definitions cannot be fetched (the reason on stderr); 2 for bad usage.
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const tool = path.join(here, "rr_robdef_node.cjs");
const SERVICE_INDEX = "RobotRaconteurServiceIndex";

const usage = `usage: rr-robdef ts [-o DIR] [--dts] [-I DIR]... (--url RR_URL | --gateway HTTP_URL --device NAME | --definitions FILE|-) [FILE...]
       rr-robdef ts|check|format ...   (service definition files; as the native rr-robdef)
  --url rr+ws://HOST:PORT/?service=NAME   connect and take the service's definitions (node < 22: needs the ws package)
  --gateway http://HOST:PORT --device NAME   GET /api/devices/NAME/definitions of rr-gateway's JSON API
  --definitions FILE   a JSON file (- for stdin): {"definitions": [text, ...]}, [text, ...] or {name: text}
  --username U --password P   the login for --url; --token T (or $RR_GATEWAY_TOKEN) a bearer token for --gateway
  --timeout-ms N   connect / request timeout (default 15000)`;

function fail(message, status = 1) {
  process.stderr.write(`rr-robdef: ${message}\n`);
  process.exit(status);
}

/** The definition texts in `json` (the JSON API's shapes), as a list. */
function textsOf(json, where) {
  const list = Array.isArray(json) ? json : Array.isArray(json?.definitions) ? json.definitions
    : json && typeof json === "object" ? Object.values(json) : null;
  if (!list || !list.every((t) => typeof t === "string"))
    fail(`${where}: expected {"definitions": [text, ...]}, [text, ...] or {name: text}`);
  return list;
}

async function fromUrl(url, options) {
  const { connect } = await import("./robotraconteur.mjs");
  let root;
  try {
    root = await connect(url, options);
  } catch (e) {
    fail(`${url}: ${e.errorName ?? "error"}: ${e.message}`);
  }
  const defs = Object.values(root.$definitions);
  await root.$client.close().catch(() => {});
  return defs;
}

async function fromGateway(gateway, device, token, timeoutMs) {
  const base = gateway.replace(/\/+$/, "");
  const url = `${base}/api/devices/${encodeURIComponent(device)}/definitions`;
  let r;
  try {
    r = await fetch(url, { headers: token ? { Authorization: `Bearer ${token}` } : {}, signal: AbortSignal.timeout(timeoutMs) });
  } catch (e) {
    fail(`GET ${url}: ${e.cause?.message ?? e.message}`);
  }
  const body = await r.text();
  if (!r.ok) fail(`GET ${url}: HTTP ${r.status}${body ? `: ${body.slice(0, 300)}` : ""}`);
  let json;
  try {
    json = JSON.parse(body);
  } catch {
    fail(`GET ${url}: not JSON`);
  }
  const texts = textsOf(json, `GET ${url}`);
  if (!texts.length) fail(`GET ${url}: the device has no definitions yet (not connected since the gateway started?)`);
  return texts;
}

function fromFile(file) {
  let text;
  try {
    text = fs.readFileSync(file === "-" ? 0 : file, "utf8");
  } catch (e) {
    fail(`${file}: ${e.message}`);
  }
  try {
    return textsOf(JSON.parse(text), file);
  } catch (e) {
    return fail(`${file}: not JSON (${e.message})`);
  }
}

function runTool(args) {
  if (!fs.existsSync(tool)) fail(`${tool} is missing (a package built without the rr-robdef tool)`);
  // --no-experimental-fetch: the tool's Emscripten loader would fetch() its .wasm by path under node 18+
  const r = spawnSync(process.execPath, ["--no-experimental-fetch", tool, ...args], { stdio: "inherit" });
  if (r.error) fail(r.error.message);
  return r.status ?? 1;
}

async function main(argv) {
  if (argv[0] !== "ts") return runTool(argv);
  const pass = ["ts"];
  let url, gateway, device, definitions, username, password, token = process.env.RR_GATEWAY_TOKEN, timeoutMs = 15000;
  for (let i = 1; i < argv.length; i++) {
    const a = argv[i];
    const value = () => (i + 1 < argv.length ? argv[++i] : fail(`${a} needs a value\n${usage}`, 2));
    if (a === "--url") url = value();
    else if (a === "--gateway") gateway = value();
    else if (a === "--device") device = value();
    else if (a === "--definitions") definitions = value();
    else if (a === "--username") username = value();
    else if (a === "--password") password = value();
    else if (a === "--token") token = value();
    else if (a === "--timeout-ms") timeoutMs = Number(value());
    else if (a === "-h" || a === "--help") return process.stdout.write(`${usage}\n`), 0;
    else if (a === "-o" || a === "-I" || a === "--builtin") pass.push(a, value());
    else pass.push(a);
  }
  const sources = [url, gateway, definitions].filter((x) => x !== undefined).length;
  if (sources > 1) fail(`--url, --gateway and --definitions exclude each other\n${usage}`, 2);
  if (gateway !== undefined && !device) fail(`--gateway needs --device NAME\n${usage}`, 2);
  if (device !== undefined && gateway === undefined) fail(`--device goes with --gateway\n${usage}`, 2);
  if (!(Number.isInteger(timeoutMs) && timeoutMs > 0)) fail("--timeout-ms must be a positive integer", 2);
  if (!sources) return runTool(pass);

  const texts = url !== undefined ? await fromUrl(url, { timeoutMs, username, password })
    : gateway !== undefined ? await fromGateway(gateway, device, token, timeoutMs) : fromFile(definitions);
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "rr-robdef-"));
  try {
    const files = [];
    for (const text of texts) {
      const name = /^\s*service\s+([A-Za-z_][A-Za-z0-9_.]*)\s*$/m.exec(text)?.[1];
      if (!name) fail(`a definition without a "service NAME" line:\n${text.slice(0, 200)}`);
      if (name === SERVICE_INDEX) continue;  // the tool has it built in
      const file = path.join(tmp, `${name}.robdef`);
      fs.writeFileSync(file, text);
      files.push(file);
    }
    // the tool follows imports from these files' folder, so every fetched definition is found
    return runTool([...pass, ...files]);
  } finally {
    fs.rmSync(tmp, { recursive: true, force: true });
  }
}

main(process.argv.slice(2)).then((status) => process.exit(status), (e) => fail(e?.stack ?? String(e)));

// The JSON WebSocket's binary pushes read by the JavaScript of docs/json-api.md ("Binary pushes"), taken
// from the document itself, against rr-gateway and its demo webcam: the same FrameStream subscribed with
// and without "binary", frames compared field by field, and the binary message's size against the text.
//
// Usage: node test/gateway/binary_push_js.mjs --gateway PATH
import { spawn } from "node:child_process";
import { mkdtempSync, readFileSync, rmSync } from "node:fs";
import { createRequire } from "node:module";
import { tmpdir } from "node:os";
import { dirname, join } from "node:path";
import { createInterface } from "node:readline";
import { fileURLToPath } from "node:url";

const root = join(dirname(fileURLToPath(import.meta.url)), "..", "..");
const arg = (name) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : undefined;
};
let WebSocket;
try {
  WebSocket = createRequire(join(root, "web", "package.json"))("ws");
} catch {
  console.log("SKIP: web/node_modules/ws missing (run ./scripts/setup.sh)");
  process.exit(77);
}

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures++;
}

// The reader exactly as the document shows it.
const doc = readFileSync(join(root, "docs", "json-api.md"), "utf8");
const block = doc.match(/```js\n([\s\S]*?function readBinaryPush[\s\S]*?)```/);
if (!block) throw new Error("docs/json-api.md has no js block with readBinaryPush");
const readBinaryPush = new Function(`${block[1]}\nreturn readBinaryPush;`)();

const home = mkdtempSync(join(tmpdir(), "rr-binary-push-"));
const gw = spawn(arg("--gateway"), ["--no-local", "--listen", "127.0.0.1", "--port", "0", "--log-level", "warning"], {
  stdio: ["ignore", "pipe", "inherit"],
  env: { ...process.env, HOME: home, XDG_RUNTIME_DIR: home },
});
const stop = () => {
  if (gw.exitCode === null && gw.signalCode === null) gw.kill("SIGTERM");
  rmSync(home, { recursive: true, force: true });
};
process.on("exit", stop);
const timeout = setTimeout(() => {
  console.log("FAIL timed out after 90 s");
  process.exit(1);
}, 90000);

const port = await new Promise((resolve, reject) => {
  gw.on("exit", (code) => reject(new Error(`rr-gateway exited early with ${code}`)));
  createInterface({ input: gw.stdout }).on("line", (line) => {
    try {
      const o = JSON.parse(line);
      if ("port" in o) resolve(o.port);
    } catch {
      // not the ready line
    }
  });
});
for (let i = 0; ; i++) {
  try {
    if ((await fetch(`http://127.0.0.1:${port}/readyz`)).ok) break;
  } catch {
    // not listening yet
  }
  if (i > 300) throw new Error("the gateway never became ready");
  await new Promise((r) => setTimeout(r, 100));
}

const ws = new WebSocket(`ws://127.0.0.1:${port}/`, "rr-gateway.json.v1");
ws.binaryType = "arraybuffer";
await new Promise((resolve, reject) => {
  ws.once("open", resolve);
  ws.once("error", reject);
});
const waiting = [];
const received = [];
ws.on("message", (data, isBinary) => {
  let msg;
  if (isBinary) {
    // ws hands an ArrayBuffer with binaryType "arraybuffer", as a browser does.
    msg = readBinaryPush(data);
    msg.$bytes = data.byteLength;
    msg.$binary = true;
  } else {
    msg = JSON.parse(data.toString());
    msg.$bytes = data.length;
  }
  received.push(msg);
  for (const w of [...waiting]) {
    if (w.pred(msg)) {
      waiting.splice(waiting.indexOf(w), 1);
      w.resolve(msg);
    }
  }
});
const next = (pred) =>
  new Promise((resolve) => {
    const found = received.find(pred);
    if (found) return resolve(found);
    waiting.push({ pred, resolve });
  });
let nextId = 1;
async function request(msg) {
  const id = nextId++;
  ws.send(JSON.stringify({ id, ...msg }));
  return next((m) => m.id === id);
}

const cam = { device: "webcam", object: "Webcams[0]" };
const asText = await request({ op: "subscribe", ...cam, member: "FrameStream" });
const asBinary = await request({ op: "subscribe", ...cam, member: "FrameStream", binary: true });
check(asText.result && asBinary.result, "two subscriptions to FrameStream: " + JSON.stringify([asText, asBinary]));
await request({ op: "call", ...cam, member: "StartStreaming" });
const textFrame = await next((m) => m.subscription === asText.result.subscription && m.kind === "pipe");
const binFrame = await next((m) => m.subscription === asBinary.result.subscription && m.kind === "pipe");
await request({ op: "call", ...cam, member: "StopStreaming" });

check(!textFrame.$binary && Array.isArray(textFrame.value.data), "without binary: a text push, data a JSON array");
check(binFrame.$binary === true, "with binary: a binary message");
const v = binFrame.value;
check(v.data instanceof Uint8Array, "data is a Uint8Array over the message (" + Object.prototype.toString.call(v.data) + ")");
check(v.width === textFrame.value.width && v.height === textFrame.value.height && v.step === textFrame.value.step,
  `width, height, step as in the text push (${v.width}x${v.height}, step ${v.step})`);
check(v.data.length === v.height * v.step && v.data.length === textFrame.value.data.length,
  `data has height*step = ${v.height * v.step} bytes`);
check(v.data.every((b, i) => b >= 0 && b <= 255) && v.data.byteOffset % 8 === 0, "bytes in range, the view 8-aligned");
check(binFrame.$bytes < v.data.length + 1024, `the binary message is ${binFrame.$bytes} bytes for ${v.data.length} bytes of pixels`);
check(textFrame.$bytes > 2 * binFrame.$bytes, `the text push is ${textFrame.$bytes} bytes`);

ws.close();
clearTimeout(timeout);
console.log(failures ? `${failures} check(s) failed` : "all checks passed");
process.exit(failures ? 1 : 0);

// Object paths in the wasm client: parseObjectPath (the C++ core's parser, base/names/object_path.hpp,
// compiled into the built package) on good paths and on every error the core gives for a path a user
// types, with the core's messages; resolveObject (src/subscription.mjs, the subscriptions' walk through
// objrefs) on a root whose objrefs record what they were asked for: indexes decoded, int32 indexes as
// numbers, and its own errors. Runs with the BUILT package (wasm-client/dist); no service needed.
//
// Usage: node object_path_test.mjs
// Exit: 0 all passed, 1 a check failed, 2 the package is missing, 77 emscripten absent (package cannot be built).
import { spawnSync } from "node:child_process";
import { existsSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const dist = join(here, "..", "dist");
if (!existsSync(join(dist, "robotraconteur.mjs"))) {
  if (spawnSync("sh", ["-c", "command -v emcmake"]).status !== 0) {
    console.log("SKIP: emscripten is not installed, so wasm-client/dist cannot be built (run scripts/setup.sh)");
    process.exit(77);
  }
  console.error(`${dist}/robotraconteur.mjs missing: run wasm-client/build.sh (scripts/test.sh does)`);
  process.exit(2);
}
const { parseObjectPath, RRError } = await import(pathToFileURL(join(dist, "robotraconteur.mjs")).href);
const { resolveObject } = await import(pathToFileURL(join(dist, "subscription.mjs")).href);

let failed = 0;
let passed = 0;
function check(cond, what) {
  if (cond) passed++;
  else {
    failed++;
    console.log(`FAIL: ${what}`);
  }
}
const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);
async function rejection(promise) {
  try {
    await promise;
  } catch (e) {
    return e;
  }
  return null;
}

// Good paths: segments with decoded indexes; no `index` without brackets.
const good = [
  ["child", [{ name: "child" }]],
  ["child_by_int[7].leaf", [{ name: "child_by_int", index: "7" }, { name: "leaf" }]],
  ["child_by_int[-1]", [{ name: "child_by_int", index: "-1" }]],
  ["child_by_int[%2d1]", [{ name: "child_by_int", index: "-1" }]],  // service-path encoding, decoded
  ["child_by_name[with space.and dots].leaf", [{ name: "child_by_name", index: "with space.and dots" }, { name: "leaf" }]],
  ["a.b[x].c[key]", [{ name: "a" }, { name: "b", index: "x" }, { name: "c", index: "key" }]],
];
for (const [path, want] of good) {
  const got = await parseObjectPath(path);
  check(same(got, want), `parseObjectPath(${JSON.stringify(path)}) = ${JSON.stringify(got)}, want ${JSON.stringify(want)}`);
}

// Every error of a typed path (base/names/object_path.hpp lists them), with the core's message.
const bad = [
  ["", 'object path "" is empty'],
  ["a..b", 'object path "a..b": expected a member name at offset 2'],
  [".a", 'object path ".a": expected a member name at offset 0'],
  ["[1]", 'object path "[1]": expected a member name at offset 0'],
  ["arms[x", "object path \"arms[x\": '[' without ']'"],
  ["arms[]", 'object path "arms[]": empty index'],
  ["arms]", "object path \"arms]\": unexpected ']' at offset 4"],
  ["a[1]b", "object path \"a[1]b\": unexpected 'b' at offset 4"],
  ["a-b", "object path \"a-b\": unexpected '-' at offset 1"],
  ["a.", "object path \"a.\" ends with '.'"],
];
for (const [path, message] of bad) {
  const e = await rejection(parseObjectPath(path));
  check(e instanceof RRError && e.errorName === "RobotRaconteur.InvalidArgument" && e.message === message,
    `parseObjectPath(${JSON.stringify(path)}) rejects with InvalidArgument "${message}", got ${e ? `${e.errorName}: ${e.message}` : "no error"}`);
}

// resolveObject: each objref's get() records the index it was given and returns the next object.
const asked = [];
function object(type, members) {
  const o = { $type: type, $members: members.map(([name, kind, index]) => ({ name, kind, index: index ?? null })) };
  for (const [name, kind, , next] of members)
    if (kind === "objref") o[name] = { get: async (index) => (asked.push([type, name, index]), next()) };
  return o;
}
const leaf = object("t.Leaf", [["value", "property"]]);
const child = object("t.Child", [["leaf", "objref", null, () => leaf]]);
const root = object("t.Root", [
  ["child_by_int", "objref", "int32", () => child],
  ["child_by_name", "objref", "string", () => child],
  ["child", "objref", null, () => child],
  ["value", "property"],
]);

check((await resolveObject(root, "")) === root, `resolveObject(root, "") is the root`);
asked.length = 0;
check((await resolveObject(root, "child_by_int[%2d1].leaf")) === leaf, "child_by_int[%2d1].leaf reaches the leaf");
check(asked.length === 2 && same(asked[0], ["t.Root", "child_by_int", -1]) && asked[1][1] === "leaf" && asked[1][2] === undefined,
  `an int32 index is a number, no index undefined: ${JSON.stringify(asked)}`);
check(typeof asked[0]?.[2] === "number", "the int32 index is passed as a number");
asked.length = 0;
await resolveObject(root, "child_by_name[a.b c].leaf");
check(asked[0]?.[2] === "a.b c", `a string index is passed as its text: ${JSON.stringify(asked)}`);

const walkErrors = [
  ["child..leaf", "RobotRaconteur.InvalidArgument", 'object path "child..leaf": expected a member name at offset 6'],
  ["value", "RobotRaconteur.MemberNotFound", 'no objref "value" on t.Root'],
  ["nosuch.leaf", "RobotRaconteur.MemberNotFound", 'no objref "nosuch" on t.Root'],
  ["child.value", "RobotRaconteur.MemberNotFound", 'no objref "value" on t.Child'],
  ["child_by_int[seven]", "RobotRaconteur.InvalidArgument",
    'object path "child_by_int[seven]": objref "child_by_int" takes an int32 index, not "seven"'],
  ["child_by_int[2147483648]", "RobotRaconteur.InvalidArgument",
    'object path "child_by_int[2147483648]": objref "child_by_int" takes an int32 index, not "2147483648"'],
];
for (const [path, name, message] of walkErrors) {
  asked.length = 0;
  const e = await rejection(resolveObject(root, path));
  check(e instanceof RRError && e.errorName === name && e.message === message,
    `resolveObject(${JSON.stringify(path)}) rejects with ${name} "${message}", got ${e ? `${e.errorName}: ${e.message}` : "no error"}`);
}
const lowest = await rejection(resolveObject(root, "child_by_int[-2147483648]"));
check(lowest === null, `the lowest int32 is an index: ${lowest?.message}`);

console.log(`object paths: ${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);

// Checks a recording's `json` channels the way Foxglove and Lichtblick read them (docs/recording.md
// "Opening a recording in Foxglove or Lichtblick"). Neither app runs here, and their channel parser
// (@foxglove/mcap-support) is not published on npm, so its rules are restated below, each with the file
// it comes from; the file is read with the reference reader @mcap/core (test/mcap/node_modules).
//
//   node test/record/foxglove_json_check.mjs FILE... [--max-messages N]
//
// Prints one JSON line {"channels", "messages", "numeric_fields"} and exits 0, or prints every
// violation ("FAIL: topic: ...") and exits 1. Exit 77 ("SKIP: ...") when @mcap/core is not installed.
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const require = createRequire(join(here, '../mcap/package.json'));
let McapIndexedReader, zstd, foxgloveSchemas;
try {
  ({ McapIndexedReader } = require('@mcap/core'));
  zstd = require('@foxglove/wasm-zstd');
  foxgloveSchemas = require('@foxglove/schemas/jsonschema');
} catch (e) {
  console.log(`SKIP: test/mcap/node_modules incomplete (run ./scripts/setup.sh): ${e.message}`);
  process.exit(77);
}
await zstd.isLoaded;

const failures = [];
const fail = (topic, what) => failures.push(`FAIL: ${topic}: ${what}`);

// Source: packages/mcap-support/src/parseJsonSchema.ts (foxglove/studio 9abf665,
// Lichtblick-Suite/lichtblick 660985e), function addFieldsRecursive. Returns the numeric leaf paths (what
// the Plot panel can plot) and reports what that function would throw on.
function checkObjectSchema(topic, schema, path, numeric) {
  // Rule 1: every object schema, the root included, has "type": "object" (a type array such as
  // ["object", "null"] is refused: `schema.type !== "object"` throws).
  if (schema?.type !== 'object') return fail(topic, `${path || '(root)'}: "type" must be "object", is ${JSON.stringify(schema?.type)}`);
  // Rule 2: its fields are Object.entries(schema.properties): an object without "properties" throws.
  if (schema.properties === null || typeof schema.properties !== 'object')
    return fail(topic, `${path || '(root)'}: an object schema needs "properties"`);
  for (const [name, field] of Object.entries(schema.properties)) {
    const at = path ? `${path}.${name}` : name;
    // Rule 3: "oneOf" is read before "type": only alternatives with numeric "const" (an enum) pass.
    if (Array.isArray(field.oneOf)) {
      if (!field.oneOf.every((a) => typeof a.const === 'number')) fail(topic, `${at}: oneOf alternatives must be numeric consts`);
      continue;
    }
    // Rule 4: "$ref" is not followed; the field's own "type" decides, so {"$ref": ...} alone throws.
    if ('$ref' in field && field.type === undefined) { fail(topic, `${at}: "$ref" is not followed`); continue; }
    switch (field.type) {
      case 'boolean': break;
      case 'string':
        // Rule 5: a string's contentEncoding is absent or "base64" (then decoded to bytes, a uint8 array).
        if (field.contentEncoding !== undefined && field.contentEncoding !== 'base64')
          fail(topic, `${at}: unsupported contentEncoding ${JSON.stringify(field.contentEncoding)}`);
        break;
      // Rule 6: "number" and "integer" are numbers (float64; foxglove/studio reads integer as uint32).
      case 'number': case 'integer': numeric.push(at); break;
      // Rule 7: a nested object is read by the same rules.
      case 'object': checkObjectSchema(topic, field, at, numeric); break;
      case 'array': {
        // Rule 8: an array's "items" has one type: boolean, string (no contentEncoding), number, integer
        // or object; an array of arrays, or items without a type, throws.
        const items = field.items;
        const type = items?.type;
        if (type === 'boolean') break;
        if (type === 'string') {
          if (items.contentEncoding !== undefined) fail(topic, `${at}[]: contentEncoding is refused for array items`);
          break;
        }
        if (type === 'number' || type === 'integer') { numeric.push(`${at}[]`); break; }
        if (type === 'object') { checkObjectSchema(topic, items, `${at}[]`, numeric); break; }
        fail(topic, `${at}[]: unsupported array item type ${JSON.stringify(type)}`);
        break;
      }
      // Rule 9: "null", a type array (e.g. ["number", "string"]) or no type throws.
      default: fail(topic, `${at}: unsupported type ${JSON.stringify(field.type)}`);
    }
  }
}

// Source: parseChannel.ts (same packages): a json message is JSON.parse(text) and then postprocessed,
// which assumes an object at the top; base64 fields are decoded with @protobufjs/base64 and a length
// mismatch throws. Checks a message against the field types the parser derived.
function checkMessage(topic, schema, value, path) {
  if (value === null || typeof value !== 'object' || Array.isArray(value))
    return fail(topic, `${path || 'message'}: must be a JSON object, is ${JSON.stringify(value)?.slice(0, 40)}`);
  for (const [name, field] of Object.entries(schema.properties ?? {})) {
    const v = value[name];
    if (v === undefined || v === null) continue;  // the parser skips absent and null fields
    const at = path ? `${path}.${name}` : name;
    if (field.type === 'string' && field.contentEncoding === 'base64') {
      const b = Buffer.from(v, 'base64');
      if (typeof v !== 'string' || b.toString('base64').replace(/=+$/, '') !== v.replace(/=+$/, ''))
        fail(topic, `${at}: not valid base64`);
    } else if (field.type === 'object') {
      checkMessage(topic, field, v, at);
    } else if (field.type === 'array') {
      if (!Array.isArray(v)) fail(topic, `${at}: declared an array, is ${typeof v}`);
      else if (field.items?.type === 'object') v.forEach((item, i) => item !== null && checkMessage(topic, field.items, item, `${at}[${i}]`));
    } else if (field.type === 'number' || field.type === 'integer') {
      // Numbers written as strings ("NaN", big integers) are shown as text and not plotted: allowed.
      if (typeof v !== 'number' && typeof v !== 'string') fail(topic, `${at}: declared a number, is ${typeof v}`);
    }
  }
}

// Images: the Image panel takes channels whose schema name is foxglove.RawImage or
// foxglove.CompressedImage; their messages must be valid against the official schemas (@foxglove/schemas).
function checkImageMessage(topic, schemaName, msg) {
  const official = schemaName === 'foxglove.RawImage' ? foxgloveSchemas.RawImage : foxgloveSchemas.CompressedImage;
  for (const key of official.required) if (!(key in msg)) fail(topic, `missing required ${key}`);
  const t = msg.timestamp;
  if (!t || !Number.isInteger(t.sec) || !Number.isInteger(t.nsec) || t.sec < 0 || t.nsec < 0 || t.nsec > 999999999)
    fail(topic, `timestamp must be {sec, nsec} with nsec in [0, 1e9): ${JSON.stringify(t)}`);
  for (const [k, p] of Object.entries(official.properties)) {
    if (!(k in msg)) continue;
    if (p.type === 'integer' && !(Number.isInteger(msg[k]) && msg[k] >= (p.minimum ?? -Infinity))) fail(topic, `${k}: integer >= ${p.minimum}`);
    if (p.type === 'string' && typeof msg[k] !== 'string') fail(topic, `${k}: must be a string`);
  }
  if (schemaName === 'foxglove.RawImage' && typeof msg.data === 'string') {
    const bytes = Buffer.from(msg.data, 'base64').length;
    if (bytes < msg.step * msg.height) fail(topic, `data has ${bytes} bytes, step*height is ${msg.step * msg.height}`);
  }
}

const args = process.argv.slice(2);
let maxMessages = 50;
const files = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--max-messages') maxMessages = Number(args[++i]);
  else files.push(args[i]);
}
if (files.length === 0) { console.error('usage: foxglove_json_check.mjs FILE... [--max-messages N]'); process.exit(2); }

const summary = { channels: 0, messages: 0, numeric_fields: {}, image_channels: [] };
for (const file of files) {
  const bytes = readFileSync(file);
  const readable = { size: async () => BigInt(bytes.length), read: async (o, n) => bytes.subarray(Number(o), Number(o + n)) };
  const reader = await McapIndexedReader.Initialize({
    readable, decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) } });
  const jsonChannels = new Map();
  for (const channel of reader.channelsById.values()) {
    if (channel.messageEncoding !== 'json') continue;
    const topic = channel.topic;
    const schema = reader.schemasById.get(channel.schemaId);
    // parseChannel.ts: a json channel needs a schema of encoding "jsonschema" (else it throws); the
    // schema data is JSON.parse'd and must be an object; the schema's name is the root type's name.
    if (!schema || schema.encoding !== 'jsonschema') { fail(topic, `schema encoding must be jsonschema, is ${schema?.encoding}`); continue; }
    let parsed;
    try { parsed = JSON.parse(new TextDecoder().decode(schema.data)); } catch (e) { fail(topic, `schema is not JSON: ${e.message}`); continue; }
    if (parsed === null || typeof parsed !== 'object' || Array.isArray(parsed)) { fail(topic, 'schema must be a JSON object'); continue; }
    const numeric = [];
    const before = failures.length;
    checkObjectSchema(topic, parsed, '', numeric);
    if (failures.length > before) continue;
    summary.channels++;
    summary.numeric_fields[topic] = numeric.length;
    if (schema.name === 'foxglove.RawImage' || schema.name === 'foxglove.CompressedImage') summary.image_channels.push(topic);
    jsonChannels.set(channel.id, { topic, parsed, schemaName: schema.name, seen: 0 });
  }
  for await (const message of reader.readMessages()) {
    const c = jsonChannels.get(message.channelId);
    if (!c || c.seen >= maxMessages) continue;
    c.seen++;
    summary.messages++;
    let value;
    try { value = JSON.parse(new TextDecoder().decode(message.data)); } catch (e) { fail(c.topic, `message is not JSON: ${e.message}`); continue; }
    checkMessage(c.topic, c.parsed, value, '');
    if (c.schemaName.startsWith('foxglove.')) checkImageMessage(c.topic, c.schemaName, value);
  }
}
if (failures.length) {
  for (const f of failures.slice(0, 50)) console.log(f);
  console.log(`${failures.length} violation(s)`);
  process.exit(1);
}
console.log(JSON.stringify(summary));

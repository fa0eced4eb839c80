// The TypeScript reference MCAP implementation (@mcap/core, zstd from @foxglove/wasm-zstd) as the other
// side of test/mcap/mcap_interop.py: writes the interop sample, or dumps a file as JSON, in the same
// shapes as rr_mcap_tool (see its header comment).
//
//   node mcap_reference.mjs write-sample OUT [--compression zstd|none] [--chunked yes|no] [--chunk-size N]
//   node mcap_reference.mjs dump FILE [--stream]
// dump reads with McapIndexedReader (a file with a summary) or, with --stream, McapStreamReader, which
// stops at the end of a truncated file and reports where ("truncated").
import { readFileSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { McapIndexedReader, McapStreamReader, McapWriter, TempBuffer } from '@mcap/core';

const require = createRequire(import.meta.url);
const zstd = require('@foxglove/wasm-zstd');
await zstd.isLoaded;

const T0 = 1700000000000000000n;
const decompressHandlers = { zstd: (data, size) => zstd.decompress(data, Number(size)) };
const hex = (bytes) => Buffer.from(bytes).toString('hex');
const text = (s) => new TextEncoder().encode(s);

function options(args) {
  const o = {};
  for (let i = 0; i + 1 < args.length; i += 2) o[args[i].replace(/^--/, '')] = args[i + 1];
  return o;
}

async function writeSample(out, args) {
  const o = options(args);
  const buffer = new TempBuffer();
  const zstdChunks = (o.compression ?? 'zstd') === 'zstd';
  const writer = new McapWriter({
    writable: buffer,
    useChunks: (o.chunked ?? 'yes') === 'yes',
    chunkSize: Number(o['chunk-size'] ?? 4096),
    compressChunk: zstdChunks ? (data) => ({ compression: 'zstd', compressedData: zstd.compress(data, 3) }) : undefined,
  });
  await writer.start({ profile: '', library: 'mcap_reference.mjs' });
  const schemaId = await writer.registerSchema({
    name: 'experimental.sample.Sample', encoding: 'jsonschema',
    data: text('{"type":"object","properties":{"i":{"type":"integer"}}}'),
  });
  const json = await writer.registerChannel({
    topic: 'sample/json', messageEncoding: 'json', schemaId,
    metadata: new Map([['device', 'sample'], ['member', 'json']]),
  });
  const rr = await writer.registerChannel({ topic: 'sample/rr', messageEncoding: 'robotraconteur', schemaId: 0, metadata: new Map() });
  const count = Number(o.count ?? 200);
  for (let i = 0; i < count; i++) {
    let data;
    if (i % 2 === 0) data = text(`{"i":${i}}`);
    else data = Uint8Array.from({ length: i % 300 }, (_, k) => (i + k) % 256);
    const t = T0 + BigInt(i) * 1000003n;
    await writer.addMessage({ channelId: i % 2 === 0 ? json : rr, sequence: Math.floor(i / 2), logTime: t, publishTime: t - 7n, data });
  }
  await writer.end();
  writeFileSync(out, buffer.get());
}

function summaryJson(header, schemas, channels) {
  const out = { header: { profile: header.profile, library: header.library }, schemas: {}, channels: {} };
  for (const s of schemas.values()) out.schemas[s.name] = { encoding: s.encoding, data: hex(s.data) };
  for (const c of channels.values()) {
    out.channels[c.topic] = {
      message_encoding: c.messageEncoding,
      schema: c.schemaId === 0 ? '' : schemas.get(c.schemaId)?.name ?? '',
      metadata: Object.fromEntries(c.metadata),
    };
  }
  return out;
}

const row = (channels, m) => [channels.get(m.channelId).topic, m.sequence, String(m.logTime), String(m.publishTime), hex(m.data)];

async function dumpIndexed(file) {
  const bytes = readFileSync(file);
  const reader = await McapIndexedReader.Initialize({ readable: new TempBuffer(bytes), decompressHandlers });
  const out = summaryJson(reader.header, reader.schemasById, reader.channelsById);
  out.indexed = true;
  out.truncated = null;
  out.messages = [];
  for await (const m of reader.readMessages({ validateCrcs: true })) out.messages.push(row(reader.channelsById, m));
  return out;
}

function dumpStream(file) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(readFileSync(file));
  const schemas = new Map();
  const channels = new Map();
  let header;
  const messages = [];
  for (let r; (r = reader.nextRecord()) !== undefined;) {
    if (r.type === 'Header') header = r;
    else if (r.type === 'Schema') schemas.set(r.id, r);
    else if (r.type === 'Channel') channels.set(r.id, r);
    else if (r.type === 'Message') messages.push(row(channels, r));
  }
  const out = summaryJson(header, schemas, channels);
  out.indexed = false;
  out.truncated = reader.done() ? null : `${reader.bytesRemaining()} bytes left unread`;
  out.messages = messages;
  return out;
}

const [command, file, ...rest] = process.argv.slice(2);
try {
  if (command === 'write-sample') await writeSample(file, rest);
  else if (command === 'dump') console.log(JSON.stringify(rest.includes('--stream') ? dumpStream(file) : await dumpIndexed(file)));
  else {
    console.error('usage: node mcap_reference.mjs write-sample OUT [...] | dump FILE [--stream]');
    process.exit(2);
  }
} catch (e) {
  console.error(`mcap_reference.mjs: ${e.message}`);
  process.exit(1);
}

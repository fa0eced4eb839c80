// Rewrites a gateway recording with the TypeScript reference writer (@mcap/core, from test/mcap's
// node_modules): every schema, every `robotraconteur` channel and its messages, zstd chunks of 8 KiB.
// The result is "a file written by @mcap/core" for record_replay_test.py to replay.
//
//   node rewrite_with_mcap_core.mjs IN OUT
import { readFileSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(here, '..', 'mcap', 'package.json'));
const { McapIndexedReader, McapWriter, TempBuffer } = require('@mcap/core');
const zstd = require('@foxglove/wasm-zstd');
await zstd.isLoaded;

const [input, output] = process.argv.slice(2);
const reader = await McapIndexedReader.Initialize({
  readable: new TempBuffer(readFileSync(input)),
  decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) },
});
const out = new TempBuffer();
const writer = new McapWriter({
  writable: out,
  chunkSize: 8192,
  compressChunk: (data) => ({ compression: 'zstd', compressedData: zstd.compress(data, 3) }),
});
await writer.start({ profile: '', library: '@mcap/core (rewrite_with_mcap_core.mjs)' });
const schemaIds = new Map();
for (const [id, s] of reader.schemasById) schemaIds.set(id, await writer.registerSchema({ name: s.name, encoding: s.encoding, data: s.data }));
const channelIds = new Map();
for (const [id, c] of reader.channelsById) {
  if (c.messageEncoding !== 'robotraconteur') continue;
  channelIds.set(id, await writer.registerChannel({
    topic: c.topic, messageEncoding: c.messageEncoding, schemaId: schemaIds.get(c.schemaId) ?? 0, metadata: c.metadata,
  }));
}
let n = 0;
for await (const m of reader.readMessages({ validateCrcs: true })) {
  if (!channelIds.has(m.channelId)) continue;
  await writer.addMessage({ ...m, channelId: channelIds.get(m.channelId) });
  n++;
}
await writer.end();
writeFileSync(output, out.get());
console.log(JSON.stringify({ messages: n, channels: channelIds.size }));

// A Robot Raconteur client for node with the WebAssembly package (wasm-client/, README there):
// connect, read a property, call a function, read a wire, handle errors.
//
//   npm install ../../wasm-client/dist ws        # or the tarball of `npm pack wasm-client/dist`
//   node client.mjs 'rr+ws://127.0.0.1:8080/?service=create'
import { connect, RRError } from "robotraconteur-wasm";

const url = process.argv[2] ?? "rr+ws://127.0.0.1:8080/?service=create";
let create;
try {
  create = await connect(url, { timeoutMs: 10000 });  // node: the `ws` package is used for WebSockets
} catch (e) {
  console.error(`connect failed: ${e.errorName ?? e.name}: ${e.message}`);
  process.exit(1);
}
console.log(`connected to ${url}: ${create.$type}`);

console.log(`DistanceTraveled = ${await create.DistanceTraveled.get()} mm`);   // property
await create.Drive(200, 32767);                                               // function
console.log("Drive(200, 32767): ok");

try {
  await create.Drive(1.5);                                                    // wrong arguments
} catch (e) {
  if (!(e instanceof RRError)) throw e;
  console.log(`Drive(1.5): ${e.errorName} (as expected)`);
}

const packets = await create.packets.connect();                               // wire
const packet = await packets.waitInValue(5000);
console.log(`packets: ID ${packet.ID}, ${packet.Data.length} data bytes, sent at ${packets.inValueTime.seconds} s`);
await packets.close();

await create.$client.close();
console.log("done");

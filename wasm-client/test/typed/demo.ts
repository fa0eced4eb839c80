// Typed use of the demo devices (experimental.create, experimental.createwebcam; types from
// `rr-robdef ts --builtin ...` in gen/demo): every member kind, and each value checked at run time to be
// what its declared type says (the assertion helpers take exactly the declared type, so tsc checks the
// declaration and the run checks the value). `node demo.js rr+ws://HOST:PORT/` (rr-gateway's base URL).
import WebSocket from "ws";
import { connect, subscribe, type ReadonlyWireSubscription, type ReadonlyPipeSubscription, type SubscriptionClient } from "robotraconteur-wasm";
import type { Create, SensorPacket } from "./gen/demo/experimental.create.js";
import { Create as CreateConstants } from "./gen/demo/experimental.create.js";
import type { WebcamHost, Webcam, WebcamImage, WebcamImage_size } from "./gen/demo/experimental.createwebcam.js";

function check(ok: boolean, what: string): void {
  if (!ok) throw new Error(`typed demo: ${what}`);
  console.log(`ok: ${what}`);
}
const isInt = (x: number, what: string) => check(typeof x === "number" && Number.isInteger(x), `${what} is a number (${x})`);
const isU8 = (x: Uint8Array, what: string) => check(x instanceof Uint8Array, `${what} is a Uint8Array (${x.length})`);

async function main(base: string): Promise<void> {
  const create = await connect<Create>(`${base}?service=create`, { WebSocket });
  check(create.$type === "experimental.create.Create", `connect<Create>: ${create.$type}`);
  isInt(await create.DistanceTraveled.get(), "property DistanceTraveled (int32)");
  isInt(await create.Bumpers.get(), "property Bumpers (uint8)");
  await create.Drive(200, CreateConstants.DRIVE_STRAIGHT);
  check(CreateConstants.DRIVE_STRAIGHT === 32767, "constant Create.DRIVE_STRAIGHT from the generated .js");
  const off: () => void = create.Bump.on(() => {});
  off();
  const w = await create.packets.connect();
  const pkt: SensorPacket | null = await w.waitInValue(10000);
  check(pkt !== null, "wire packets: an InValue");
  if (pkt) {
    isInt(pkt.ID, "SensorPacket.ID (uint8)");
    isU8(pkt.Data, "SensorPacket.Data (uint8[])");
    check(Object.keys(pkt).sort().join() === "Data,ID", "SensorPacket has exactly its fields");
  }
  const peeked = await create.packets.peekInValueWithTime();
  check(peeked.value !== null && typeof peeked.ts.seconds === "number", "wire peekInValueWithTime");
  await w.close();
  create.play_callback.set(async (dist: number, angle: number) => Uint8Array.of(dist & 0xff, angle & 0xff));
  create.play_callback.set(null);
  await create.$client.close();

  const host = await connect<WebcamHost>(`${base}?service=webcam`, { WebSocket });
  const names = await host.WebcamNames.get();
  check(names instanceof Map && [...names.keys()].every((k) => typeof k === "number") && [...names.values()].every((v) => typeof v === "string"),
    `property WebcamNames (string{int32}) is a Map<number, string>: ${JSON.stringify([...(names ?? [])])}`);
  const cam: Webcam = await host.Webcams.get(0);
  check(typeof (await cam.Name.get()) === "string", "objref Webcams[0] → Webcam, property Name");
  const ep = await cam.FrameStream.connect();
  await cam.StartStreaming();
  const frame: WebcamImage | null | undefined = await ep.receive();
  await cam.StopStreaming();
  check(frame != null, "pipe FrameStream: a packet");
  if (frame) {
    isInt(frame.width, "WebcamImage.width");
    isInt(frame.step, "WebcamImage.step");
    isU8(frame.data, "WebcamImage.data");
    check(frame.data.length === frame.step * frame.height, "frame size");
  }
  await ep.close();
  const size: WebcamImage_size | null = await cam.CaptureFrameToBuffer();
  check(size !== null && Number.isInteger(size.height), "function CaptureFrameToBuffer → WebcamImage_size");
  const n: number = await cam.buffer.length();
  isU8(await cam.buffer.read(0, Math.min(8, n)), "memory buffer read (uint8[])");
  const dims: number[] = await cam.multidimbuffer.dimensions();
  const md = await cam.multidimbuffer.read(dims.map(() => 0), dims.map(() => 1));
  check(md.array instanceof Uint8Array && md.dims.every((d) => d === 1), `memory multidimbuffer (uint8[*]): dims ${dims}, read {dims, array: Uint8Array}`);
  await host.$client.close();

  // Subscriptions typed by the service: member names checked, values typed (misuse.ts has the wrong uses).
  const sub = subscribe<Create>(`${base}?service=create`, { WebSocket });
  sub.onConnect((_client, proxy: Create) => void proxy.StartStreaming());   // the device's state, restored on every connection
  const packets: ReadonlyWireSubscription<SensorPacket | null> = sub.subscribeWire("packets");
  check(await packets.waitInValueValid(10000), "subscribe<Create>().subscribeWire(\"packets\"): an InValue");
  const value: SensorPacket | null = packets.inValue;
  check(value !== null && Number.isInteger(value.ID) && value.Data instanceof Uint8Array, "its value is a SensorPacket");
  const offBump: () => void = sub.subscribeEvent("Bump", (client: SubscriptionClient<Create>) => void client.url);
  offBump();
  sub.setCallback("play_callback", async (dist: number, angle: number, _client: SubscriptionClient<Create>) => Uint8Array.of(dist & 0xff, angle & 0xff));
  await (await sub.getDefaultClientWait(10000)).StopStreaming();
  await sub.close();

  const hosts = subscribe<WebcamHost>(`${base}?service=webcam`, { WebSocket });
  hosts.onConnect(async (_client, proxy: WebcamHost) => (await proxy.Webcams.get(0)).StartStreaming());
  const stream: ReadonlyPipeSubscription<WebcamImage | null> = hosts.subscribePipe("FrameStream", "Webcams[0]", 4);
  const image = await stream.receivePacket(10000);
  check(image != null && image.data instanceof Uint8Array && image.data.length === image.step * image.height,
    "subscribe<WebcamHost>().subscribePipe(\"FrameStream\", \"Webcams[0]\"): a WebcamImage");
  await (await (await hosts.getDefaultClientWait(10000)).Webcams.get(0)).StopStreaming();
  await hosts.close();
}

main(process.argv[2] ?? "rr+ws://127.0.0.1:8080/").then(
  () => console.log("typed demo: all ok"),
  (e: unknown) => {
    console.error(e);
    process.exit(1);
  });

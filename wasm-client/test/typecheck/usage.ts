// Every member kind of the package's API, typed by index.d.ts: `tsc --noEmit` checks this file against
// the packed package (test/package_test.mjs), which then compiles and runs it against rr-gateway's demo
// devices: `node usage.js rr+ws://HOST:PORT/` (the gateway's base URL; devices "create" and "webcam").
import WebSocketImpl from "ws";
import {
  connect, RRError, WEBSOCKET_PROTOCOL,
  type ObjectProxy, type PropertyMember, type EventMember, type WireMember, type WireConnection,
  type CallbackMember, type PipeMember, type PipeEndpoint, type ObjRefMember, type MemoryMember,
  type MemberInfo, type TimeSpec,
} from "robotraconteur-wasm";

interface SensorPacket { ID: number; Data: Uint8Array }
interface WebcamImage { width: number; height: number; step: number; data: Uint8Array }

function check(ok: boolean, what: string): void {
  if (!ok) throw new Error(`usage: ${what}`);
  console.log(`ok: ${what}`);
}

async function main(base: string): Promise<void> {
  check(WEBSOCKET_PROTOCOL === "robotraconteur.robotraconteur.com", "the WebSocket subprotocol");
  const create: ObjectProxy = await connect(`${base}?service=create`, { timeoutMs: 15000, WebSocket: WebSocketImpl });
  check(create.$type === "experimental.create.Create", `connected to ${create.$client.url} (${create.$client.nodeName})`);
  const members: MemberInfo[] = create.$members;
  check(members.some((m) => m.kind === "wire" && m.name === "packets"), "$members lists the wire");

  // property
  const distance: PropertyMember<number> = create.DistanceTraveled;
  const d0: number = await distance.get();
  check(Number.isInteger(d0), `property DistanceTraveled = ${d0}`);

  // function
  const drive: (velocity: number, radius: number) => Promise<void> = create.Drive;
  await drive(200, 32767);
  check(true, "function Drive(200, DRIVE_STRAIGHT)");

  // event
  const bump: EventMember = create.Bump;
  const off: () => void = bump.on(() => console.log("bump"));
  off();
  check(true, "event Bump: subscribed and unsubscribed");

  // wire
  const packets: WireMember<SensorPacket> = create.packets;
  const w: WireConnection<SensorPacket> = await packets.connect();
  const first: SensorPacket = await w.waitInValue(10000);
  const ts: TimeSpec = w.inValueTime;
  check(first.Data instanceof Uint8Array && ts.seconds > 0, `wire packets: InValue ID ${first.ID} at ${ts.seconds} s`);
  const peeked: { value: SensorPacket; ts: TimeSpec } = await packets.peekInValueWithTime();
  check(typeof peeked.value.ID === "number", "wire peekInValueWithTime");
  await w.close();

  // callback
  const play: CallbackMember = create.play_callback;
  play.set(async (dist: number, angle: number) => new Uint8Array([dist & 0xff, angle & 0xff]));
  play.set(null);
  check(true, "callback play_callback: set and cleared");

  // errors: an RR error is an RRError with the RR error name
  try {
    await create.Drive(1, 2, 3);
    check(false, "Drive with three arguments must fail");
  } catch (e: unknown) {
    check(e instanceof RRError && e.errorName.startsWith("RobotRaconteur."), `error: ${(e as RRError).errorName}: ${(e as RRError).message}`);
  }
  try {
    await connect(`${base}?service=no_such_device`, { timeoutMs: 10000, WebSocket: WebSocketImpl });
    check(false, "connecting to a missing service must fail");
  } catch (e: unknown) {
    check(e instanceof RRError, `connect error: ${(e as RRError).errorName}`);
  }
  await create.$client.close();
  check(create.$client.state === "closed", "closed");

  // objref, pipe, memory on the webcam device (root WebcamHost, objref Webcams{int32})
  const host: ObjectProxy = await connect(`${base}?service=webcam`, { WebSocket: WebSocketImpl });
  const webcams: ObjRefMember = host.Webcams;
  const cam: ObjectProxy = await webcams.get(0);
  check(cam.$type === "experimental.createwebcam2.Webcam" || cam.$type.endsWith(".Webcam"), `objref Webcams[0]: ${cam.$type}`);
  const frames: PipeMember<WebcamImage> = cam.FrameStream;
  const ep: PipeEndpoint<WebcamImage> = await frames.connect();
  await cam.StartStreaming();
  const frame: WebcamImage | undefined = await ep.receive();
  await cam.StopStreaming();
  check(frame !== undefined && frame.data.length === frame.step * frame.height, `pipe FrameStream: ${frame?.width}x${frame?.height}`);
  await ep.close();
  const size: { width: number; height: number; step: number } = await cam.CaptureFrameToBuffer();
  const buffer: MemoryMember = cam.buffer;
  const n: number = await buffer.length();
  const bytes: Uint8Array = await buffer.read(0, Math.min(16, n));
  check(n >= size.step * size.height && bytes.length === Math.min(16, n), `memory buffer: ${n} bytes`);
  await host.$client.close();
}

main(process.argv[2] ?? "rr+ws://127.0.0.1:8080/").then(
  () => console.log("usage: all ok"),
  (e: unknown) => {
    console.error(e);
    process.exit(1);
  });

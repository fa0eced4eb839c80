// Wrong uses of generated types that tsc must reject, each for its own reason: typed_test.mjs checks
// that every MISUSE line gets the error code and message fragment written after it, and no other line
// gets any error.
import { connect, subscribe, type Wire, type Property } from "robotraconteur-wasm";
import type { Create, SensorPacket } from "./gen/demo/experimental.create.js";
import type { WebcamHost } from "./gen/demo/experimental.createwebcam.js";
import type { Root, Inner } from "./gen/interop/experimental.interop_test.js";
import type { Robot, RobotState } from "robotraconteur-wasm/std/com.robotraconteur.robotics.robot";

export async function wrong(url: string): Promise<void> {
  const create = await connect<Create>(url);
  const root = await connect<Root>(url);
  const robot = await connect<Robot>(url);
  const p: SensorPacket = { ID: 1, Data: [1, 2] };                  // MISUSE TS2740 Type 'number[]' is missing the following properties from type 'Uint8Array'
  const i: Inner = { id: "1", label: "x", values: Float64Array.of() }; // MISUSE TS2322 Type 'string' is not assignable to type 'number'
  await create.Drive(200);                                           // MISUSE TS2554 Expected 2 arguments, but got 1
  await create.DistanceTraveled.set(3);                              // MISUSE TS2339 Property 'set' does not exist on type 'ReadonlyProperty<number>'
  const w: Wire<RobotState> = robot.robot_state;                     // MISUSE TS2739 Type 'ReadonlyWire<RobotState | null>' is missing the following properties from type 'WireMember<RobotState>'
  const wn: Wire<number> = root.w_both;                              // MISUSE TS2322 Type 'Float64Array' is not assignable to type 'number'
  const big: number = await root.p_int64.get();                      // MISUSE TS2322 Type 'bigint' is not assignable to type 'number'
  const s: Inner = await root.s_inner.get();                         // MISUSE TS2322 Type 'null' is not assignable to type 'Inner'
  const pr: Property<string> = root.p_double;                        // MISUSE TS2322 Type 'number' is not assignable to type 'string'
  await root.w_sink.connect().then((c) => c.inValue);                // MISUSE TS2339 Property 'inValue' does not exist on type 'WriteonlyWireConnection<number>'
  const ep = await root.p_stream.connect();
  await ep.send(Float64Array.of(1));                                 // MISUSE TS2339 Property 'send' does not exist on type 'ReadonlyPipeEndpoint<Float64Array>'
  await root.mem_ro.write(0, Uint8Array.of(1));                      // MISUSE TS2339 Property 'write' does not exist on type 'ReadonlyArrayMemory<Uint8Array>'
  root.cb_compute.set((x: string) => 1);                             // MISUSE TS2345 Types of parameters 'x' and 'x' are incompatible
  await root.child_by_int.get("alpha");                              // MISUSE TS2345 Argument of type 'string' is not assignable to parameter of type 'number'
  const sub = subscribe<Create>(url);
  sub.subscribeWire("packetz");                                      // MISUSE TS2345 Argument of type '"packetz"' is not assignable to parameter of type '"packets"'
  sub.subscribeEvent("Bumpp", () => {});                             // MISUSE TS2345 Argument of type '"Bumpp"' is not assignable to parameter of type '"Bump"'
  sub.subscribeWire("Bump");                                         // MISUSE TS2345 Argument of type '"Bump"' is not assignable to parameter of type '"packets"'
  const id: string = sub.subscribeWire("packets").inValue;          // MISUSE TS2322 Type 'SensorPacket | null' is not assignable to type 'string'
  sub.subscribeWire("packets").setOutValueAll(null);                 // MISUSE TS2339 Property 'setOutValueAll' does not exist on type 'ReadonlyWireSubscription<SensorPacket | null>'
  sub.setCallback("play_callback", (d: string) => Uint8Array.of());  // MISUSE TS2345 Types of parameters 'd' and 'DistanceTraveled' are incompatible
  const hosts = subscribe<WebcamHost>(url);
  hosts.subscribePipe("FrameStream", "Webcamz[0]");                  // MISUSE TS2345 is not an objref path of the subscribed object
  hosts.subscribePipe("FrameStreem", "Webcams[0]");                  // MISUSE TS2345 Argument of type '"FrameStreem"' is not assignable to parameter of type '"FrameStream"'
  void [p, i, w, wn, big, s, pr, id];
}

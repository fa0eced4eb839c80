// Subscriptions and the JSON client as a TypeScript user writes them (README.md "Subscriptions"):
// type-checked (tsc --noEmit --strict) by package_test.mjs, never run (reconnect_test.mjs runs them).
import { subscribe, RRError, type ObjectProxy, type ServiceSubscription, type WireSubscription, type PipeSubscription, type TimeSpec } from "robotraconteur-wasm";
import { connectJson, type JsonSubscription } from "robotraconteur-wasm/json";

interface SensorPacket { ID: number; Data: Uint8Array }

export async function subscriptions(gateway: string): Promise<string> {
  const sub: ServiceSubscription = subscribe(`rr+ws://${gateway}/?service=create`, {
    backoff: { initialMs: 500, maxMs: 10000, jitter: 0.25 }, heartbeatPeriodMs: 10000, receiveTimeoutMs: 15000,
  });
  const offConnect = sub.onConnect((client, proxy: ObjectProxy) => console.log(client.url, client.connectCount, proxy.$type));
  sub.onDisconnect((client, error: RRError | null) => console.log(client.state, error?.errorName));
  sub.onError((error, client) => console.log(error.message, client?.id));
  const packets: WireSubscription<SensorPacket> = sub.subscribeWire("packets");  // untyped: any, assigned to what it is
  packets.onValueChanged((v: SensorPacket, ts: TimeSpec) => console.log(v.ID, ts.seconds));
  const ok: boolean = await packets.waitInValueValid(5000);
  const id: number | undefined = packets.tryGetInValue()?.value.ID;
  const frames: PipeSubscription<Uint8Array> = sub.subscribePipe("FrameStream", "Webcams[0]", 10);
  const frame: Uint8Array | undefined = await frames.receivePacket(1000);
  const offBump = sub.subscribeEvent("Bump", () => console.log("bump"));
  sub.setCallback("play_callback", async (distance: number, angle: number) => new Uint8Array([distance, angle]));
  const create = await sub.getDefaultClientWait(10000);
  await create.Drive(200, 1000);
  const found = subscribe({ gateway: `http://${gateway}`, serviceTypes: ["experimental.create.Create"], attributes: { Location: /^lab/ } });
  const state: "connecting" | "connected" | "closed" = found.state;
  offConnect();
  offBump();
  await sub.close();
  await found.close();

  const json = connectJson(`http://${gateway}`, { backoff: { initialMs: 500 }, timeoutMs: 15000 });
  const dev = json.device<{ DistanceTraveled: number; packets: SensorPacket }>("create");
  const distance: number = await dev.get("DistanceTraveled");
  const s: JsonSubscription<SensorPacket> = await dev.subscribe("packets", (p) => console.log(p.ID));
  await s.close();
  json.close();
  return `${ok} ${id} ${frame?.length} ${state} ${distance}`;
}

// The standard definitions' types as the package ships them ("robotraconteur-wasm/std/<service>",
// generated at build time): tsc --strict only (no robot here to run against).
import { connect } from "robotraconteur-wasm";
import type { Robot, RobotState, RobotInfo } from "robotraconteur-wasm/std/com.robotraconteur.robotics.robot";
import { RobotCommandMode } from "robotraconteur-wasm/std/com.robotraconteur.robotics.robot";
import type { Camera } from "robotraconteur-wasm/std/com.robotraconteur.imaging";
import type { Image } from "robotraconteur-wasm/std/com.robotraconteur.image";
import type { TrajectoryStatus } from "robotraconteur-wasm/std/com.robotraconteur.robotics.trajectory";
import type { Pose } from "robotraconteur-wasm/std/com.robotraconteur.geometry";

export async function robot(url: string): Promise<number> {
  const r = await connect<Robot>(url);
  const info: RobotInfo | null = await r.robot_info.get();
  const joints = info?.joint_info?.length ?? 0;
  await r.command_mode.set(RobotCommandMode.jog);                // enum value from the generated .js
  const speed: number = await r.speed_ratio.get();
  const w = await r.robot_state.connect();                       // readonly wire
  const state: RobotState | null = await w.waitInValue(1000);
  const q: Float64Array | undefined = state?.joint_position;
  const flags: bigint | undefined = state?.robot_state_flags;    // uint64
  const pose: Pose | undefined = state?.kin_chain_tcp?.[0];      // namedarray
  await r.jog_joint(Float64Array.of(0.1), 0.5, false);           // function
  for await (const s of await r.execute_trajectory(null)) {      // generator
    const st: TrajectoryStatus | null = s;
    void st;
  }
  const off = r.tool_changed.on((chain: number, name: string) => console.log(chain, name));  // event
  off();
  const pc = await r.position_command.connect();                 // writeonly wire
  pc.outValue = null;
  return joints + speed + (q?.length ?? 0) + Number(flags ?? 0n) + (pose ? 1 : 0);
}

export async function camera(url: string): Promise<number> {
  const cam = await connect<Camera>(url);
  const img: Image | null = await cam.capture_frame();
  const ep = await cam.frame_stream.connect();                   // readonly pipe
  const next: Image | null | undefined = await ep.receive();
  return (img?.data.length ?? 0) + (next?.image_info?.width ?? 0);
}

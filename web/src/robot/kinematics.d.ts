// Declarations of kinematics.js (forward kinematics of a RobotInfo's chains), for the package's users:
// import { chainModel, forwardKinematics } from "robotraconteur-wasm/robot/kinematics.js".

/** [x, y, z] in metres (or a unit axis). */
export type Vec3 = [number, number, number];
/** 3x3 rotation matrix, row-major. */
export type Matrix3 = number[];
export interface RigidTransform { R: Matrix3; p: Vec3 }
/** A Pose as the wasm client gives com.robotraconteur.geometry.Pose: quaternion w first, position in metres. */
export interface PoseValue {
  position: { x: number; y: number; z: number };
  orientation: { w: number; x: number; y: number; z: number };
}
export type JointKind = "revolute" | "continuous" | "prismatic";

/** One kinematic chain of a RobotInfo, checked. */
export interface ChainModel {
  name: string;
  /** Which joints of the robot's joint vector drive the chain, in order. */
  jointNumbers: number[];
  joints: Array<{ axis: Vec3; type: JointKind; name: string }>;
  /** P: one more than joints, metres. */
  links: Vec3[];
  /** device_info.device_origin_pose (identity when absent). */
  base: RigidTransform;
  /** The chain's flange_pose (identity when absent). */
  flange: RigidTransform;
  /** The chain's current_tool.tcp, or null. */
  tool: RigidTransform | null;
}

export interface ForwardKinematicsResult {
  /** What a driver on the official abstract robot reports as kin_chain_tcp (flange, then the tool). */
  tcp: PoseValue;
  /** The tool flange, without the tool. */
  flange: PoseValue;
  /** Each joint's origin and unit axis in the base frame, before the joint moves. */
  joints: Array<{ position: Vec3; axis: Vec3; type: JointKind; name: string }>;
  /** The links as a polyline: base origin, the end of each P vector and of each prismatic slide, the flange. */
  points: Vec3[];
  flangeTransform: RigidTransform;
  tcpTransform: RigidTransform;
}

/** Chain `index` of a RobotInfo value. Throws an Error saying what cannot be used (H/P missing or of the wrong length, ...). */
export function chainModel(info: unknown, index?: number): ChainModel;
/** Every chain that can be used, and one message per chain that cannot. Never throws. */
export function robotModel(info: unknown): { chains: ChainModel[]; errors: string[] };
/** Forward kinematics at the robot's joint vector (radians, metres). Throws when q lacks a joint of the chain. */
export function forwardKinematics(model: ChainModel, q: ArrayLike<number>): ForwardKinematicsResult;
/** Distance (m) and rotation angle (rad) between two poses. */
export function poseDifference(a: PoseValue, b: PoseValue): { distance: number; angle: number };
export function transformToPose(t: RigidTransform): PoseValue;
export function rotate(R: Matrix3, v: Vec3): Vec3;
export function matmul(A: Matrix3, B: Matrix3): Matrix3;
export function axisAngleToMatrix(k: Vec3, theta: number): Matrix3;
/** Rotation matrix of a unit quaternion [w, x, y, z]. */
export function quaternionToMatrix(q: [number, number, number, number]): Matrix3;
/** Unit quaternion [w, x, y, z], w ≥ 0. */
export function matrixToQuaternion(R: Matrix3): [number, number, number, number];

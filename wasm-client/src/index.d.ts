// Types of the Robot Raconteur WebAssembly client (robotraconteur.mjs). Values follow README.md "Values".

/** An RR error. `errorName` is the RR error name, e.g. "RobotRaconteur.InvalidArgument", or a user
 *  exception name such as "experimental.interop_test.InteropError"; `code` the MessageErrorType number. */
export class RRError extends Error {
  constructor(errorName: string, message: string, code?: number);
  readonly errorName: string;
  readonly code: number;
}

/** Any RR value as JS (typed by the member's robdef; see README.md "Values"). */
export type RRValue = any;

export interface TimeSpec {
  /** Seconds since 1970-01-01 UTC. */
  seconds: number;
  nanoseconds: number;
}

export type MemberKind = "property" | "function" | "event" | "objref" | "pipe" | "callback" | "wire" | "memory";

export interface MemberInfo {
  name: string;
  kind: MemberKind;
  /** Value / return type as robdef text, e.g. "double[]" ("void" for events). */
  type: string;
  params: { name: string; type: string }[];
  generator: boolean;
  readonly: boolean;
  writeonly: boolean;
  /** objrefs: the index kind ("int32", "string") or null. */
  index?: "int32" | "string" | null;
  /** memories: true for multi-dim memories. */
  multidim?: boolean;
}

export interface ClientHandle {
  /** Disconnects; resolves once closed. */
  close(): Promise<void>;
  readonly state: "connecting" | "connected" | "closed";
  /** `fn(error)` once the connection is closed (by close(), the service or the network). Returns the remover. */
  onClose(fn: (error: RRError) => void): () => void;
  /** The service node's NodeName and NodeID (text). */
  readonly nodeName: string;
  readonly nodeId: string;
  readonly url: string;
}

export interface PropertyMember<T = RRValue> {
  get(): Promise<T>;
  set(value: T): Promise<void>;
}

export interface Generator<T = RRValue, P = RRValue> extends AsyncIterable<T> {
  /** The next value; rejects with RRError "RobotRaconteur.StopIteration" at the end. */
  next(param?: P): Promise<T>;
  close(): Promise<void>;
  abort(): Promise<void>;
}

export interface EventMember {
  /** `fn(...params)` for every event; returns the function that unsubscribes. */
  on(fn: (...args: RRValue[]) => void): () => void;
}

export interface ObjRefMember {
  /** The object (index: int32 or string for indexed objrefs). */
  get(index?: number | string): Promise<ObjectProxy>;
}

export interface CallbackMember {
  /** Sets the handler (may be async; a thrown RRError keeps its errorName); null clears it. */
  set(fn: ((...args: RRValue[]) => RRValue | Promise<RRValue>) | null): void;
}

export interface PipeEndpoint<T = RRValue> extends AsyncIterable<T> {
  /** The index the service assigned. */
  readonly index: number;
  readonly closed: boolean;
  /** `fn(packet)` for every packet (first those queued so far); while any listener is set, packets are not queued for iteration. */
  onPacket(fn: (packet: T) => void): () => void;
  onClose(fn: (error: RRError | null) => void): () => void;
  /** `fn(packetNumber)` for every acknowledgement the service sends. */
  onAck(fn: (packetNumber: number) => void): () => void;
  /** The next queued packet; undefined once closed. */
  receive(): Promise<T | undefined>;
  /** Sends a packet; resolves with its packet number. */
  send(value: T): Promise<number>;
  close(): Promise<void>;
}

export interface PipeMember<T = RRValue> {
  /** index −1 (default): the service chooses. */
  connect(index?: number): Promise<PipeEndpoint<T>>;
}

export interface WireConnection<T = RRValue> {
  /** The newest InValue; throws RRError "RobotRaconteur.ValueNotSet" when none is valid. */
  readonly inValue: T;
  readonly inValueTime: TimeSpec;
  readonly inValueValid: boolean;
  /** Setting sends a new OutValue. */
  outValue: T;
  readonly outValueTime: TimeSpec;
  /** Lifespan of InValue and OutValue in ms (−1 = forever). */
  lifespanMs: number;
  /** Resolves with the InValue once one is valid. */
  waitInValue(timeoutMs?: number): Promise<T>;
  onChange(fn: (value: T, ts: TimeSpec) => void): () => void;
  onClose(fn: (error: RRError | null) => void): () => void;
  readonly closed: boolean;
  close(): Promise<void>;
}

export interface WireMember<T = RRValue> {
  connect(): Promise<WireConnection<T>>;
  peekInValue(): Promise<T>;
  peekOutValue(): Promise<T>;
  peekInValueWithTime(): Promise<{ value: T; ts: TimeSpec }>;
  pokeOutValue(value: T): Promise<void>;
}

export interface MemoryMember {
  /** Items of an array memory. */
  length(): Promise<number>;
  /** Shape of a multi-dim memory. */
  dimensions(): Promise<number[]>;
  dimCount(): Promise<number>;
  /** Array memory: items [start, start+count) as a typed array (objects for pod/namedarray memories).
   *  Multi-dim memory: read([start…], [count…]) → {dims, array} (column-major). */
  read(start: number | number[], count: number | number[]): Promise<RRValue>;
  write(start: number | number[], data: RRValue): Promise<void>;
}

export interface ObjectProxy {
  /** Qualified object type, e.g. "experimental.create.Create". */
  readonly $type: string;
  /** Service path of the object. */
  readonly $path: string;
  readonly $implements: string[];
  readonly $members: MemberInfo[];
  /** Service definitions the client holds: name → robdef text. */
  readonly $definitions: Record<string, string>;
  readonly $client: ClientHandle;
  /** Takes the object's monitor lock (timeoutMs −1: wait as long as it takes). */
  $monitorEnter(timeoutMs?: number): Promise<void>;
  $monitorExit(): Promise<void>;
  /** Members by name: PropertyMember, function, EventMember, ObjRefMember, PipeMember, CallbackMember,
   *  WireMember or MemoryMember according to the member's kind. */
  [member: string]: any;
}

export interface ConnectOptions {
  /** Connect and per-request timeout in ms (default 15000). */
  timeoutMs?: number;
  username?: string;
  password?: string;
  /** This client's NodeName (default: none). */
  nodeName?: string;
  /** WebSocket class to use (default: globalThis.WebSocket, else the `ws` package in node). */
  WebSocket?: any;
  /** Node only, rr+wss only: PEM certificate(s) the server's chain must lead to, used instead of node's
   *  built-in CA list (node's `--use-openssl-ca` flag makes that list the system's). A browser uses its
   *  own trust store and rejects this option with InvalidArgument. */
  ca?: string | Uint8Array | Array<string | Uint8Array>;
}

/** Connects to `url` (`rr+ws://host:port/?service=name`, or rr+wss) and returns the root object's proxy. */
export function connect(url: string, options?: ConnectOptions): Promise<ObjectProxy>;

/** Loads the WebAssembly module (connect() does it on first use). */
export function loadModule(): Promise<unknown>;

/** Subprotocol of RR over WebSocket. */
export const WEBSOCKET_PROTOCOL: string;

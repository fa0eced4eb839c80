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

/** A type-only mark on the member proxy types: the member's kind and value type, which the typed
 *  subscription methods read (WireNames, ...). Never present at run time; not exported. */
declare const memberMark: unique symbol;
interface Mark<Kind extends string, Value, Direction extends "both" | "readonly" | "writeonly" = "both"> {
  kind: Kind;
  value: Value;
  direction: Direction;
}

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
  /** The WebSocket close code once the server closed the socket (1001 Going Away: the server is
   *  stopping, e.g. for a restart; 1006: no close frame, e.g. a crash or a cut network), else null. */
  readonly closeCode: number | null;
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
  readonly [memberMark]?: Mark<"event", RRValue[]>;
  /** `fn(...params)` for every event; returns the function that unsubscribes. */
  on(fn: (...args: RRValue[]) => void): () => void;
}

export interface ObjRefMember {
  readonly [memberMark]?: Mark<"objref", ObjectProxy>;
  /** The object (index: int32 or string for indexed objrefs). */
  get(index?: number | string): Promise<ObjectProxy>;
}

export interface CallbackMember {
  readonly [memberMark]?: Mark<"callback", (...args: RRValue[]) => RRValue>;
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
  readonly [memberMark]?: Mark<"pipe", T>;
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
  readonly [memberMark]?: Mark<"wire", T>;
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

/** What every object proxy has, typed or not: the generated interfaces (`rr-robdef ts`) extend it. */
export interface ObjectBase {
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
  /** The member `name`, as the proxy's property of that name would be. A member named `then` is
   *  reached only this way: as a property it would make the proxy a thenable, which `await` calls.
   *  Throws RRError `RobotRaconteur.MemberNotFound` for a name the object does not have. */
  $member(name: string): any;
}

/** An object proxy without generated types: members by name are `any`. */
export interface ObjectProxy extends ObjectBase {
  /** Members by name: PropertyMember, function, EventMember, ObjRefMember, PipeMember, CallbackMember,
   *  WireMember or MemoryMember according to the member's kind (a member named `then`: `$member("then")`). */
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

/** Connects to `url` (`rr+ws://host:port/?service=name`, or rr+wss) and returns the root object's proxy.
 *  `T`: the root object's generated interface (`connect<Robot>(url)`, README "Typed use"); it is not
 *  checked against the service's type (compare `$type`). Without it the proxy is an untyped ObjectProxy. */
export function connect<T extends ObjectBase = ObjectProxy>(url: string, options?: ConnectOptions): Promise<T>;

/** Loads the WebAssembly module (connect() does it on first use). */
export function loadModule(): Promise<unknown>;

/** One segment of an object path: the member name and, with brackets, the index's text (decoded). */
export interface ObjectPathSegment {
  name: string;
  index?: string;
}

/** Parses an object path (`child_by_int[7].leaf`, `arms[left arm].tool`) with the C++ core's parser, the
 *  gateway's. Rejects with RRError InvalidArgument and the core's message
 *  (`object path "a..b": expected a member name at offset 2`). */
export function parseObjectPath(path: string): Promise<ObjectPathSegment[]>;

/** Subprotocol of RR over WebSocket. */
export const WEBSOCKET_PROTOCOL: string;

// ---- Typed values and member proxies: what `rr-robdef ts` generates declarations with (README "Typed use").
// The runtime objects are the same as above; these types only narrow them by the member's robdef.

/** `cdouble` / `csingle`. */
export interface Complex {
  real: number;
  imag: number;
}

/** A multi-dim array (`T[*]`, `T[N,M]`): column-major, element (i, j) is `array[i + j*dims[0]]`. `A` is a
 *  typed array for numbers, `boolean[]` / `Complex[]`, or an array of pod/namedarray objects. */
export interface MultiDimArray<A> {
  dims: number[];
  array: A;
}

/** A `varvalue` as the package gives it: `{type, value}` with the type text as the official Python client
 *  names it (numerics always arrays). Narrow on `type`; named types (`svc.Struct`, `svc.Pod[]`, enums) are
 *  `${string}.${string}` with an untyped value. The runtime gives null for a null varvalue (a field's type
 *  says `| null`). As input the package also takes a bare string, number (→ "double[]") or typed array. */
export type VarValue =
  | { type: "double[]"; value: Float64Array }
  | { type: "single[]"; value: Float32Array }
  | { type: "int8[]"; value: Int8Array }
  | { type: "uint8[]"; value: Uint8Array }
  | { type: "int16[]"; value: Int16Array }
  | { type: "uint16[]"; value: Uint16Array }
  | { type: "int32[]"; value: Int32Array }
  | { type: "uint32[]"; value: Uint32Array }
  | { type: "int64[]"; value: BigInt64Array }
  | { type: "uint64[]"; value: BigUint64Array }
  | { type: "bool[]"; value: boolean[] }
  | { type: "cdouble[]" | "csingle[]"; value: Complex[] }
  | { type: "double[*]"; value: MultiDimArray<Float64Array> }
  | { type: "single[*]"; value: MultiDimArray<Float32Array> }
  | { type: "int8[*]"; value: MultiDimArray<Int8Array> }
  | { type: "uint8[*]"; value: MultiDimArray<Uint8Array> }
  | { type: "int16[*]"; value: MultiDimArray<Int16Array> }
  | { type: "uint16[*]"; value: MultiDimArray<Uint16Array> }
  | { type: "int32[*]"; value: MultiDimArray<Int32Array> }
  | { type: "uint32[*]"; value: MultiDimArray<Uint32Array> }
  | { type: "int64[*]"; value: MultiDimArray<BigInt64Array> }
  | { type: "uint64[*]"; value: MultiDimArray<BigUint64Array> }
  | { type: "bool[*]"; value: MultiDimArray<boolean[]> }
  | { type: "cdouble[*]" | "csingle[*]"; value: MultiDimArray<Complex[]> }
  | { type: "string"; value: string }
  | { type: "varvalue{list}"; value: Array<VarValue | null> }
  | { type: "varvalue{string}"; value: Record<string, VarValue | null> }
  | { type: "varvalue{int32}"; value: Map<number, VarValue | null> }
  | { type: `${string}.${string}`; value: unknown };

/** `property T name`. */
export type Property<T> = PropertyMember<T>;
/** `property T name [readonly]`: no set(). */
export interface ReadonlyProperty<T> {
  get(): Promise<T>;
}
/** `property T name [writeonly]`: no get(). */
export interface WriteonlyProperty<T> {
  set(value: T): Promise<void>;
}

/** `event name(A...)`: `on(fn)` with the event's parameters, e.g. `Event<[seq: number, text: string]>`. */
export interface Event<A extends unknown[]> {
  readonly [memberMark]?: Mark<"event", A>;
  /** `fn(...params)` for every event; returns the function that unsubscribes. */
  on(fn: (...args: A) => void): () => void;
}

/** `callback R name(P...)`, e.g. `Callback<(x: number) => number>`: the handler may be async. */
export interface Callback<F extends (...args: any[]) => any> {
  readonly [memberMark]?: Mark<"callback", F>;
  /** Sets the handler (a thrown RRError keeps its errorName); null clears it. */
  set(fn: ((...args: Parameters<F>) => ReturnType<F> | Promise<ReturnType<F>>) | null): void;
}

/** `objref T name`: the object's proxy. */
export interface ObjRef<T> {
  readonly [memberMark]?: Mark<"objref", T>;
  get(): Promise<T>;
}
/** `objref T{int32} name` / `T[]` (K = number), `objref T{string} name` (K = string). */
export interface IndexedObjRef<T, K extends number | string> {
  readonly [memberMark]?: Mark<"indexed objref", T>;
  get(index: K): Promise<T>;
}

/** `pipe T name`. */
export type Pipe<T> = PipeMember<T>;
/** A pipe endpoint of a `[readonly]` pipe: the service sends, the client cannot. */
export type ReadonlyPipeEndpoint<T> = Omit<PipeEndpoint<T>, "send">;
/** A pipe endpoint of a `[writeonly]` pipe: the client sends, nothing arrives. */
export type WriteonlyPipeEndpoint<T> = Omit<PipeEndpoint<T>, "receive" | "onPacket" | typeof Symbol.asyncIterator>;
/** `pipe T name [readonly]`. */
export interface ReadonlyPipe<T> {
  readonly [memberMark]?: Mark<"pipe", T, "readonly">;
  connect(index?: number): Promise<ReadonlyPipeEndpoint<T>>;
}
/** `pipe T name [writeonly]`. */
export interface WriteonlyPipe<T> {
  readonly [memberMark]?: Mark<"pipe", T, "writeonly">;
  connect(index?: number): Promise<WriteonlyPipeEndpoint<T>>;
}

/** `wire T name`. */
export type Wire<T> = WireMember<T>;
/** A connection of a `[readonly]` wire: InValue only (the service sends). */
export type ReadonlyWireConnection<T> = Omit<WireConnection<T>, "outValue" | "outValueTime">;
/** A connection of a `[writeonly]` wire: OutValue only (the client sends). */
export type WriteonlyWireConnection<T> = Omit<WireConnection<T>, "inValue" | "inValueTime" | "inValueValid" | "waitInValue" | "onChange">;
/** `wire T name [readonly]`. */
export interface ReadonlyWire<T> {
  readonly [memberMark]?: Mark<"wire", T, "readonly">;
  connect(): Promise<ReadonlyWireConnection<T>>;
  peekInValue(): Promise<T>;
  peekInValueWithTime(): Promise<{ value: T; ts: TimeSpec }>;
}
/** `wire T name [writeonly]`. */
export interface WriteonlyWire<T> {
  readonly [memberMark]?: Mark<"wire", T, "writeonly">;
  connect(): Promise<WriteonlyWireConnection<T>>;
  peekOutValue(): Promise<T>;
  pokeOutValue(value: T): Promise<void>;
}

/** `memory T[] name`: `A` is the array (a typed array, or pod/namedarray objects). */
export interface ArrayMemory<A> {
  length(): Promise<number>;
  /** Items [start, start+count). */
  read(start: number, count: number): Promise<A>;
  write(start: number, data: A): Promise<void>;
}
export type ReadonlyArrayMemory<A> = Omit<ArrayMemory<A>, "write">;
/** `memory T[*] name`. */
export interface MultiDimMemory<A> {
  dimensions(): Promise<number[]>;
  dimCount(): Promise<number>;
  read(start: number[], count: number[]): Promise<MultiDimArray<A>>;
  write(start: number[], data: MultiDimArray<A>): Promise<void>;
}
export type ReadonlyMultiDimMemory<A> = Omit<MultiDimMemory<A>, "write">;

// --- Subscriptions (subscription.mjs; README.md "Subscriptions") -------------------------------------

/** Liveness options of every connection (wire.md §6.3). */
export interface LivenessOptions {
  /** Send an RR ConnectionTest after this long (ms) without sending (default 10000). */
  heartbeatPeriodMs?: number;
  /** Close the connection (ConnectionError) after this long (ms) without receiving anything (default 15000). */
  receiveTimeoutMs?: number;
}

/** Reconnect delays: min(maxMs, initialMs·factor^n), spread uniformly by ±jitter. */
export interface BackoffOptions {
  /** First delay after a drop (default 500 ms). */
  initialMs?: number;
  /** Largest delay (default 10000 ms). */
  maxMs?: number;
  /** Growth per failed attempt (default 2). */
  factor?: number;
  /** Spread as a fraction of the delay, 0–1 (default 0.25). */
  jitter?: number;
}

export const DEFAULT_BACKOFF: Readonly<Required<BackoffOptions>>;
/** The delay before reconnect attempt `attempt` (0-based) under `backoff`. */
export function backoffDelay(attempt: number, backoff: Required<BackoffOptions>, random?: () => number): number;

/** A service as discovery describes it (the gateway's GET /api/devices and /api/discovered). */
export interface ServiceInfo {
  /** The name to connect with: the gateway device's name when a gateway device serves it. */
  name: string;
  /** The service's own name on its node. */
  serviceName: string;
  nodeName: string;
  nodeId: string;
  rootObjectType: string;
  implements: string[];
  attributes: Record<string, unknown>;
  /** The gateway device serving it, or null (then it is reached directly over rr+ws). */
  device: string | null;
  urls?: string[];
}

/** Which services a subscription keeps connections to (the official ServiceSubscriptionFilter's fields). */
export interface SubscriptionFilter {
  /** The gateway whose discovery is used: "http://host:port" (or rr+ws://host:port). */
  gateway: string;
  /** Root object type or an implemented type, e.g. "experimental.create.Create". */
  serviceTypes?: string[];
  serviceNames?: string[];
  nodes?: { nodeName?: string; nodeId?: string }[];
  /** Attribute name → text or pattern its value must match. */
  attributes?: Record<string, string | RegExp>;
  /** "all" (default) or "any" of the attributes. */
  attributesMatch?: "all" | "any";
  predicate?: (info: ServiceInfo) => boolean;
  maxConnections?: number;
}

export interface SubscribeOptions extends ConnectOptions, LivenessOptions {
  backoff?: BackoffOptions;
  /** How often (ms) a filter's matches are looked up again (default 5000). */
  discoveryIntervalMs?: number;
}

export type SubscriptionClientState = "connecting" | "connected" | "waiting" | "closed";

/** One service a subscription keeps a connection to. */
export interface SubscriptionClient<T = ObjectProxy> {
  readonly id: string;
  readonly url: string;
  readonly state: SubscriptionClientState;
  /** The root object while connected, else null. */
  readonly proxy: T | null;
  readonly serviceInfo: ServiceInfo | null;
  readonly lastError: RRError | null;
  /** Connections made so far (1 after the first, 2 after the first reconnect, ...). */
  readonly connectCount: number;
}

/** What wire and pipe subscriptions tell about their member connections (one per connected service). */
export interface MemberConnectionEvents {
  /** `fn(client)` each time the member connection to a service opens (first time, and again after each reconnect). */
  onConnect(fn: (client: SubscriptionClient) => void): () => void;
  /** `fn(client, error)` each time an open member connection closes (by the service, or with its client connection); error null when closed cleanly. */
  onDisconnect(fn: (client: SubscriptionClient, error: RRError | null) => void): () => void;
  /** `fn(error, client)` each time opening the member connection fails; it is tried again with the backoff. */
  onError(fn: (error: RRError, client: SubscriptionClient) => void): () => void;
}

export interface WireSubscription<V = RRValue> extends MemberConnectionEvents {
  /** The newest InValue from any service; throws RRError "RobotRaconteur.ValueNotSet" when none is valid. */
  readonly inValue: V;
  readonly inValueTime: TimeSpec;
  readonly inValueValid: boolean;
  /** InValue older than this many ms is not valid (−1: forever, the default). */
  inValueLifespanMs: number;
  tryGetInValue(): { value: V; ts: TimeSpec; client: SubscriptionClient } | undefined;
  /** Resolves true once an InValue is valid, false after timeoutMs (−1, the default: no limit). */
  waitInValueValid(timeoutMs?: number): Promise<boolean>;
  /** `fn(value, ts, client)` for every new InValue; returns the remover. Fires once per value. */
  onValueChanged(fn: (value: V, ts: TimeSpec, client: SubscriptionClient) => void): () => void;
  readonly activeWireConnectionCount: number;
  /** Sets the OutValue on every wire connection open now. */
  setOutValueAll(value: V): void;
  close(): Promise<void>;
}

export interface PipeSubscription<P = RRValue> extends AsyncIterable<P>, MemberConnectionEvents {
  /** Packets queued for receivePacket (at most maxBacklog; the oldest are dropped). */
  readonly available: number;
  tryReceivePacket(): P | undefined;
  /** The next packet; undefined after timeoutMs (−1, the default: no limit) or once closed. */
  receivePacket(timeoutMs?: number): Promise<P | undefined>;
  /** `fn(packet, client)` for every packet; returns the remover. */
  onPacketReceived(fn: (packet: P, client: SubscriptionClient) => void): () => void;
  readonly activePipeEndpointCount: number;
  sendPacketAll(packet: P): Promise<number[]>;
  close(): Promise<void>;
}

// --- Subscriptions typed by the service type (`subscribe<Create>(url)`): member names are checked and
// values typed from the generated interface; an untyped subscription (`subscribe(url)`) takes any name
// and gives `any` values.

/** Whether `T` is an untyped proxy (members by any name). */
type IsUntyped<T> = string extends keyof T ? true : false;
/** The mark of a member type, or never for anything else (a function, a property, ObjectBase's $…). */
type MarkOf<M> = typeof memberMark extends keyof M ? Exclude<M[typeof memberMark], undefined> : never;
/** Names of `T`'s members of kind `Kind` ("wire", "pipe", "event", "callback"); any name for an untyped proxy. */
export type MemberNames<T, Kind extends string> = IsUntyped<T> extends true
  ? string
  : { [K in keyof T & string]: [MarkOf<T[K]>] extends [never] ? never : MarkOf<T[K]> extends { kind: Kind } ? K : never }[keyof T & string];
/** Names of the wires of object type `T` (a generated interface), e.g. `"packets"`. */
export type WireNames<T> = MemberNames<T, "wire">;
/** Names of the pipes of object type `T`. */
export type PipeNames<T> = MemberNames<T, "pipe">;
/** Names of the events of object type `T`. */
export type EventNames<T> = MemberNames<T, "event">;
/** Names of the callbacks of object type `T`. */
export type CallbackNames<T> = MemberNames<T, "callback">;
/** The value type of wire or pipe `K` of `T` (`SensorPacket | null`); any for an untyped proxy. */
export type MemberValue<T, K> = IsUntyped<T> extends true ? any : K extends keyof T ? (MarkOf<T[K]> extends { value: infer V } ? V : never) : never;

/** The object type at objref path `P` ("child", "items[3]", "a.b[x]") below `T`; "" is `T` itself. An
 *  untyped proxy, a path that is not a literal, or a varobject gives ObjectProxy; a name that is not an
 *  objref of its object gives never (the subscribe methods then reject the path). */
export type ObjectAtPath<T, P extends string> = IsUntyped<T> extends true
  ? ObjectProxy
  : string extends P
    ? ObjectProxy
    : P extends ""
      ? T
      : P extends `${infer Head}.${infer Rest}`
        ? Head extends `${string}[${string}` ? (Head extends `${string}]` ? ObjectAtPath<ObjectAtSegment<T, Head>, Rest> : ObjectProxy) : ObjectAtPath<ObjectAtSegment<T, Head>, Rest>
        : ObjectAtSegment<T, P>;
type ObjectAtSegment<T, S extends string> = IsUntyped<T> extends true
  ? ObjectProxy
  : S extends `${infer Name}[${string}]`
    ? Name extends keyof T ? (MarkOf<T[Name]> extends { kind: "indexed objref"; value: infer O } ? O : never) : never
    : S extends keyof T ? (MarkOf<T[S]> extends { kind: "objref"; value: infer O } ? O : never) : never;
/** `P` when it is an objref path of `T`; else a type no string has, so that a misspelled path is a
 *  compile error naming it. */
export type ServicePathOf<T, P extends string> = [ObjectAtPath<T, P>] extends [never] ? { "is not an objref path of the subscribed object": P } : P;

type Directed<M, Full, Readonly> = MarkOf<M> extends { direction: "readonly" } ? Readonly : Full;
/** The subscription of wire `K` at path `P` of `T`: `[readonly]` wires have no setOutValueAll. */
export type WireSubscriptionOf<T, K, P extends string = ""> = IsUntyped<ObjectAtPath<T, P>> extends true
  ? WireSubscription<any>
  : K extends keyof ObjectAtPath<T, P>
    ? Directed<ObjectAtPath<T, P>[K], WireSubscription<MemberValue<ObjectAtPath<T, P>, K>>, ReadonlyWireSubscription<MemberValue<ObjectAtPath<T, P>, K>>>
    : never;
/** The subscription of pipe `K` at path `P` of `T`: `[readonly]` pipes have no sendPacketAll. */
export type PipeSubscriptionOf<T, K, P extends string = ""> = IsUntyped<ObjectAtPath<T, P>> extends true
  ? PipeSubscription<any>
  : K extends keyof ObjectAtPath<T, P>
    ? Directed<ObjectAtPath<T, P>[K], PipeSubscription<MemberValue<ObjectAtPath<T, P>, K>>, ReadonlyPipeSubscription<MemberValue<ObjectAtPath<T, P>, K>>>
    : never;
/** The parameters of event `K` of `O` (a tuple); any[] for an untyped proxy. */
export type EventArgs<O, K> = IsUntyped<O> extends true ? any[] : K extends keyof O ? (MarkOf<O[K]> extends { value: infer A extends unknown[] } ? A : never) : never;
/** The handler type of callback `K` of `O`; `(...args: any[]) => any` for an untyped proxy. */
export type CallbackFunction<O, K> = IsUntyped<O> extends true ? (...args: any[]) => any
  : K extends keyof O ? (MarkOf<O[K]> extends { value: infer F extends (...args: any[]) => any } ? F : never) : never;

/** A WireSubscription of a `[readonly]` wire: the service sends, so there is no OutValue to set. */
export type ReadonlyWireSubscription<V = RRValue> = Omit<WireSubscription<V>, "setOutValueAll">;
/** A PipeSubscription of a `[readonly]` pipe: nothing to send. */
export type ReadonlyPipeSubscription<P = RRValue> = Omit<PipeSubscription<P>, "sendPacketAll">;

/** A ServiceSubscription; `T` is the root object's type (`subscribe<Create>(url)`): member names and
 *  values of subscribeWire / subscribePipe / subscribeEvent / setCallback are checked against it, also
 *  at a literal objref path below the root. Untyped (`T` = ObjectProxy): any name, `any` values. */
export interface ServiceSubscription<T extends ObjectBase = ObjectProxy> {
  /** "connected" while at least one service is connected. */
  readonly state: "connecting" | "connected" | "closed";
  readonly clients: SubscriptionClient<T>[];
  getConnectedClients(): Map<string, T>;
  /** The first connected service's root object; throws RRError ConnectionError when none is. */
  getDefaultClient(): T;
  tryGetDefaultClient(): T | null;
  /** Waits for a connected service (timeoutMs −1, the default: no limit); rejects with ConnectionError. */
  getDefaultClientWait(timeoutMs?: number): Promise<T>;
  /** `fn(client)` as each attempt to connect to a service starts (the first, and each after a drop or a failure). */
  onConnecting(fn: (client: SubscriptionClient<T>) => void): () => void;
  /** `fn(client, proxy)` after every (re)connection: the place to restore device state (e.g. start streaming again). */
  onConnect(fn: (client: SubscriptionClient<T>, proxy: T) => void): () => void;
  onDisconnect(fn: (client: SubscriptionClient<T>, error: RRError | null) => void): () => void;
  onError(fn: (error: RRError, client: SubscriptionClient<T> | null) => void): () => void;
  /** Wire `name` of the root object, or of the object at `servicePath` (objref path below the root:
   *  "child", "items[3]"; "" (default) is the root). Typed: `WireSubscription<value type of the wire>`. */
  subscribeWire<K extends WireNames<ObjectAtPath<T, P>>, P extends string = "">(name: K, servicePath?: P & ServicePathOf<T, P>): WireSubscriptionOf<T, K, P>;
  /** Pipe `name` (at `servicePath`); `maxBacklog` packets wait for receivePacket (default 100, −1: no limit). */
  subscribePipe<K extends PipeNames<ObjectAtPath<T, P>>, P extends string = "">(name: K, servicePath?: P & ServicePathOf<T, P>, maxBacklog?: number): PipeSubscriptionOf<T, K, P>;
  /** `fn(...params, client)` for every firing on every connected service; returns the remover. */
  subscribeEvent<K extends EventNames<ObjectAtPath<T, P>>, P extends string = "">(
    name: K,
    fn: IsUntyped<ObjectAtPath<T, P>> extends true ? (...args: any[]) => void : (...args: [...EventArgs<ObjectAtPath<T, P>, K>, SubscriptionClient<T>]) => void,
    servicePath?: P & ServicePathOf<T, P>,
  ): () => void;
  /** Sets callback `name` on every service, also after reconnects (`fn(...params, client)`); null clears it. */
  setCallback<K extends CallbackNames<ObjectAtPath<T, P>>, P extends string = "">(
    name: K,
    fn: (IsUntyped<ObjectAtPath<T, P>> extends true ? (...args: any[]) => RRValue | Promise<RRValue>
      : (...args: [...Parameters<CallbackFunction<ObjectAtPath<T, P>, K>>, SubscriptionClient<T>]) =>
          ReturnType<CallbackFunction<ObjectAtPath<T, P>, K>> | Promise<ReturnType<CallbackFunction<ObjectAtPath<T, P>, K>>>) | null,
    servicePath?: P & ServicePathOf<T, P>,
  ): void;
  close(): Promise<void>;
}

/** Keeps connections to the services `target` names, reconnecting with backoff (README.md "Subscriptions"). */
export function subscribe<T extends ObjectBase = ObjectProxy>(target: string | string[] | SubscriptionFilter, options?: SubscribeOptions): ServiceSubscription<T>;
/** Whether `info` passes `filter`. */
export function matchesFilter(info: ServiceInfo, filter: Omit<SubscriptionFilter, "gateway">): boolean;
/** connect() takes the liveness options too (merged into ConnectOptions above). */
export interface ConnectOptions extends LivenessOptions {}

// Only the declarations marked `export` above are the package's (memberMark, Mark, IsUntyped, ... stay private).
export {};

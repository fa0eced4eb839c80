// Types of the gateway's JSON WebSocket API client (json_client.mjs): import from "robotraconteur-wasm/json".
// Values are JSON as in docs/json-mapping.md (typed arrays only in binary pushes).

export class RRError extends Error {
  constructor(errorName: string, message: string, code?: number);
  readonly errorName: string;
  readonly code: number;
}

/** Subprotocol of the JSON API: "rr-gateway.json.v1". */
export const JSON_PROTOCOL: string;

export interface JsonBackoffOptions {
  initialMs?: number;
  maxMs?: number;
  factor?: number;
  jitter?: number;
}

export interface JsonClientOptions {
  /** Per request, and the longest a request waits for the socket (default 15000 ms). */
  timeoutMs?: number;
  /** Reconnect delays (default 0.5 s doubling to 10 s, ±25 %). */
  backoff?: JsonBackoffOptions;
  /** Ask the gateway something after this long without receiving (default 10000 ms). */
  heartbeatPeriodMs?: number;
  /** Drop the socket and reconnect after this long without receiving (default 15000 ms). */
  receiveTimeoutMs?: number;
  /** Gateway login on every socket (op "login"). */
  username?: string;
  password?: string;
  token?: string;
  /** WebSocket class (default globalThis.WebSocket, else the `ws` package in node). */
  WebSocket?: any;
}

export interface TimeSpec {
  seconds: number;
  nanoseconds: number;
}

/** A push as the gateway sent it (docs/json-api.md "Gateway → client"). */
export interface JsonPush<V = any> {
  subscription: number;
  kind: "wire" | "event" | "pipe";
  value?: V;
  args?: Record<string, any>;
  time?: TimeSpec;
  dropped?: number;
}

export interface JsonSubscription<V = any> {
  /** "wire", "event" or "pipe" (from the robdef). */
  readonly kind: "wire" | "event" | "pipe";
  /** Times it was subscribed again on a new socket or after the gateway closed it. */
  readonly resubscribed: number;
  readonly closed: boolean;
  onClose(fn: (error: RRError) => void): () => void;
  setOutValue(value: V): Promise<void>;
  send(value: V, requestAck?: boolean): Promise<number>;
  close(): Promise<void>;
}

export interface JsonSubscribeOptions {
  /** Relative service path of an object below the root ("Webcams[0]"). */
  object?: string;
  /** Numeric arrays as typed arrays (binary pushes). */
  binary?: boolean;
  /**
   * Wires and pipes: at most this many values per second (0.01 to 1000), the newest of each window;
   * the last value is always delivered (at the start of the next window). Events refuse it.
   */
  maxRateHz?: number;
  /**
   * Pipes with `maxRateHz`: packets waiting for their window (1 to 64, default 1); the oldest are
   * dropped beyond it and counted in the next push's `dropped`.
   */
  queueLength?: number;
}

/** Operations on one device (T: a map of member name → value type, for typed use). */
export interface JsonDevice<T extends Record<string, any> = Record<string, any>> {
  readonly name: string;
  info(): Promise<any>;
  child<U extends Record<string, any> = Record<string, any>>(path: string): JsonDevice<U>;
  get<K extends keyof T & string>(member: K): Promise<T[K]>;
  set<K extends keyof T & string>(member: K, value: T[K]): Promise<void>;
  call<R = any>(member: string, args?: any[] | Record<string, any>, options?: { maxItems?: number }): Promise<R>;
  peek<K extends keyof T & string>(member: K): Promise<{ value: T[K]; time: TimeSpec }>;
  /** handler(value, push): a wire's value, an event's args object, a pipe's packet. */
  subscribe<K extends keyof T & string>(member: K, handler: (value: T[K], push: JsonPush<T[K]>) => void,
    options?: JsonSubscribeOptions): Promise<JsonSubscription<T[K]>>;
}

export interface JsonClient {
  readonly state: "connecting" | "connected" | "waiting" | "closed";
  readonly url: string;
  /** Sockets opened and made ready so far. */
  readonly connectCount: number;
  devices(): Promise<any[]>;
  device<T extends Record<string, any> = Record<string, any>>(name: string, object?: string): JsonDevice<T>;
  subscribe<V = any>(device: string, member: string, handler: (value: V, push: JsonPush<V>) => void,
    options?: JsonSubscribeOptions): Promise<JsonSubscription<V>>;
  /** Any request (docs/json-api.md); resolves with its result. */
  request(fields: Record<string, any>): Promise<any>;
  onConnect(fn: () => void): () => void;
  onDisconnect(fn: (error: RRError) => void): () => void;
  onError(fn: (error: RRError) => void): () => void;
  onDeviceState(fn: (push: { kind: "device_state"; device: string; state: string; [k: string]: any }) => void): () => void;
  close(): void;
}

/** Opens a client of the gateway's JSON API at `url` (http://host:port, ws://host:port, or "/" in a page). */
export function connectJson(url: string, options?: JsonClientOptions): JsonClient;
/** Decodes a binary push (numeric arrays as typed arrays over the buffer). */
export function decodeBinaryPush(buffer: ArrayBuffer): any;

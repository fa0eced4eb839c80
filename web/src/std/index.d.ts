// Type declarations of the standard-type modules (index.js), for TypeScript users of the client
// package: import { ... } from "robotraconteur-wasm/std". Values are as the client package gives them
// (docs: wasm-client README "Values"); see docs/dashboard.md "Standard types".

/** A value of an enum as the device's definitions declare it. */
export interface EnumValue { name: string; value: number }

/** What is wrong with a frame: codes of checkImage, checkCompressedImage and imageToBitmap. */
export interface ImageError { code: string; message: string }

/** A standard Image or CompressedImage value: the fields the decoders read. */
export interface ImageValue {
  image_info: { width: number; height: number; step: number; encoding: number | string; [field: string]: unknown };
  data: Uint8Array | Uint8ClampedArray;
}

export interface ImageOptions {
  /** The device's ImageEncoding values (the standard numbering without them). */
  encodings?: EnumValue[];
  depthRange?: { min: number; max: number };
  floatRange?: { min: number; max: number };
  out?: Uint8ClampedArray;
}

export type DecodeResult =
  | { ok: true; width: number; height: number; data: Uint8ClampedArray; encoding: string; range?: { min: number; max: number } | null; note?: string }
  | { ok: false; error: ImageError };

export interface CompressedFormat { name: string; mime: string; drawable: boolean }

export type BitmapResult =
  | { ok: true; bitmap: ImageBitmap; width: number; height: number; encoding?: string; format?: CompressedFormat;
      range?: { min: number; max: number } | null; note?: string }
  | { ok: false; error: ImageError };

export function checkImage(value: unknown, encodings?: EnumValue[]):
  | { ok: true; width: number; height: number; step: number; encoding: string; format: object; note?: string }
  | { ok: false; error: ImageError };
export function decodeImage(value: unknown, options?: ImageOptions): DecodeResult;
export function compressedFormat(data: unknown): CompressedFormat | null;
export function checkCompressedImage(value: unknown):
  | { ok: true; format: CompressedFormat; width: number; height: number }
  | { ok: false; format?: CompressedFormat; error: ImageError };
export function imageToBitmap(value: unknown, options?: ImageOptions & {
  compressed?: boolean;
  createImageBitmap?: (source: ImageBitmapSource) => Promise<ImageBitmap>;
  ImageData?: typeof ImageData;
}): Promise<BitmapResult>;
export function isCompressedEncoding(value: unknown, encodings?: EnumValue[]): boolean;
/** Any value to an ImageBitmap through its renderer's picture hooks (`compressed`, else `image`); never rejects. */
export function pictureToBitmap(value: unknown, renderer: Renderer, ctx?: RendererContext, env?: {
  createImageBitmap?: (source: ImageBitmapSource) => Promise<ImageBitmap>;
  ImageData?: typeof ImageData;
}): Promise<BitmapResult>;
export const STANDARD_IMAGE_ENCODINGS: Readonly<Record<string, number>>;
export const PIXEL_FORMATS: Readonly<Record<string, Readonly<{ kind: string; bytes: number; sample: string }>>>;
export const COMPRESSED_FORMATS: ReadonlyArray<Readonly<{ name: string; mime: string; drawable: boolean }>>;
export function encodingNames(values?: EnumValue[]): Map<number, string>;

/** Frames of a stream decoded in a Worker, the newest winning (frame_decoder.js). */
export class FrameDecoder {
  constructor(options: {
    onResult: (result: BitmapResult, meta: Record<string, unknown> & { seq: number }) => void;
    Worker?: typeof Worker | null;
    workerUrl?: string | URL;
    decode?: (value: ImageValue, options: ImageOptions & { compressed: boolean }) => Promise<BitmapResult>;
    transfer?: boolean;
  });
  readonly inWorker: boolean;
  readonly stats: { submitted: number; decoded: number; failed: number; dropped: number; refused: number };
  /** Queues a frame (decoded by `renderer`'s hooks, the standard Image / CompressedImage one by default);
   * returns the refusal ({ok: false}) when its header is wrong, else null. */
  submit(value: unknown, options?: ImageOptions & { compressed?: boolean; renderer?: Renderer; context?: RendererContext }, meta?: Record<string, unknown>):
    { ok: false; error: ImageError; format?: CompressedFormat } | null;
  dispose(): void;
}

/** The named types of a device's definitions ({ service name: robdef text }, as `$definitions`). */
export class RobdefOutline {
  constructor(definitions: Record<string, string>);
  readonly types: Map<string, OutlineEntry>;
  typeOf(name: string, scope?: string | null): OutlineEntry | null;
  enumOf(name: string, scope?: string | null): EnumValue[] | null;
  serviceOfObject(qualified: string): string | null;
}

export interface OutlineEntry {
  kind: "struct" | "pod" | "namedarray" | "object" | "enum";
  name: string;
  qualified: string;
  service: string;
  line: number;
  fields: Array<{ type: string; name: string; line: number }>;
  values: EnumValue[];
  members: Array<{ kind: string; text: string; line: number }>;
}

/** What a renderer's hooks get: the device's definitions and enums (and image options). */
export interface RendererContext extends ImageOptions {
  outline?: RobdefOutline;
  clockEnum?: EnumValue[];
  [key: string]: unknown;
}

/** A renderer of one type (registry.js): its hooks are what the dashboard shows and draws with. */
export interface Renderer {
  type: string;
  layout?: Record<string, string | string[]>;
  text?: (value: any, ctx: RendererContext) => string;
  /** The header alone (no pixel read): a bad frame refused before decoding. */
  check?: (value: any, ctx: RendererContext) => { ok: true } | { ok: false; error: ImageError };
  /** RGBA pixels ({ok, width, height, data}) or {ok: false, error}. */
  image?: (value: any, ctx: RendererContext) => DecodeResult | Promise<DecodeResult>;
  /** Bytes the browser decodes: their format, and `bytes` when they are not the value's `data`. */
  compressed?: (value: any, ctx?: RendererContext) => ReturnType<typeof checkCompressedImage> & { bytes?: Uint8Array };
  /** The frame as the image Worker takes it (std/image_worker.js); leave out to decode on the page. */
  toWorker?: (value: any, ctx: RendererContext) => object;
}

export interface TypeDescriptor {
  text: string;
  qualifiedText: string;
  base: string;
  array: "vector" | "multidim" | null;
  dims: number[] | null;
  container: "int32" | "string" | "list" | null;
  kind: "primitive" | "struct" | "pod" | "namedarray" | "enum" | "object" | "unknown";
  qualified: string | null;
  renderer?: Renderer | null;
  /** Why the device's definition does not have the renderer's layout (then no renderer). */
  mismatch?: string | null;
  element?: TypeDescriptor;
  fields?: FieldDescriptor[];
  enumValues?: EnumValue[];
}

export interface FieldDescriptor {
  name: string;
  type: TypeDescriptor;
  /** The enum of a bit-flag field. */
  flags?: EnumValue[];
  /** The sibling field naming this field's units. */
  units?: { field: string; enumValues: EnumValue[] | null };
}

export class RendererRegistry {
  register(...renderers: Array<Renderer | Renderer[]>): this;
  get(qualified: string): Renderer | null;
  has(qualified: string): boolean;
  types(): string[];
}

export class TypeDescriber {
  constructor(outline: RobdefOutline, registry?: RendererRegistry | null, annotators?: Array<(owner: object, field: object, outline: RobdefOutline) => object | null>);
  describe(text: string, scope: string): TypeDescriptor;
  describeMember(objectQualified: string, member: { name: string; type: string }): FieldDescriptor;
}

export function standardRegistry(): RendererRegistry;
export function standardDescriber(outline: RobdefOutline, registry?: RendererRegistry): TypeDescriber;
export const STANDARD_ANNOTATORS: ReadonlyArray<(owner: object, field: object, outline: RobdefOutline) => object | null>;
export function resolveName(outline: RobdefOutline, name: string, scope: string): OutlineEntry | null;
export function findNamed(outline: RobdefOutline, name: string, scope: string): OutlineEntry | null;
export function qualifyType(outline: RobdefOutline, text: string, scope: string): string;
export function fieldAt(d: TypeDescriptor, path: string): FieldDescriptor | null;

/** Context of the text functions: `now` in ms since the epoch, the device's definitions. */
export interface TextContext { now?: number; outline?: RobdefOutline }
export function typedText(value: unknown, d: TypeDescriptor | null | undefined, ctx?: TextContext, maxItems?: number): string;
export function fieldText(owner: unknown, field: FieldDescriptor, ownerDescriptor?: TypeDescriptor | null, ctx?: TextContext, maxItems?: number): string;
export function memberText(value: unknown, member: FieldDescriptor, ctx?: TextContext, maxItems?: number): string;

export function formatUuid(value: unknown): string | null;
export function isNilUuid(value: unknown): boolean;
export function uuidBytes(value: unknown): ArrayLike<number> | null;
export function formatIdentifier(value: unknown): string | null;
export function timeParts(value: unknown): { seconds: bigint; nanoseconds: number } | null;
export function timeSeconds(value: unknown): number | null;
export function isoTime(parts: { seconds: bigint; nanoseconds: number } | null, offsetSeconds?: number): string | null;
export function durationText(seconds: number): string;
export function ageText(ageSeconds: number): string;
export function comparableClock(clockType: unknown, clockEnum?: EnumValue[]): boolean;
export function formatTime(value: unknown, ctx?: { now?: number; clockEnum?: EnumValue[] }): string | null;
export function formatDuration(value: unknown): string | null;
export function quaternionToRpy(q: unknown): [number, number, number] | null;
export function formatRotation(q: unknown): string | null;
export function formatPose(value: unknown): string | null;
export function formatTransform(value: unknown): string | null;
export function enumName(values: EnumValue[] | null | undefined, n: unknown): string | null;
export function formatEnum(values: EnumValue[] | null | undefined, n: unknown): string;
export function isFlagEnum(values: EnumValue[] | null | undefined): boolean;
export function flagNames(values: EnumValue[] | null | undefined, n: unknown): string[];
export function formatFlags(values: EnumValue[] | null | undefined, n: unknown): string;
export function flagEnumFor(outline: RobdefOutline, owner: OutlineEntry, field: { name: string; type: string }): EnumValue[] | null;
/** Enum values of an integer field that holds enum codes (AdvancedRobotState's joint_position_units → JointPositionUnits). */
export function codeEnumFor(outline: RobdefOutline, owner: OutlineEntry, field: { name: string; type: string }): EnumValue[] | null;
/** "radian" for one code, "[radian, meter]" for an array of codes. */
export function formatCodes(values: EnumValue[] | null | undefined, v: number | bigint | ArrayLike<number>): string;
export function siUnitText(unit: unknown): string | null;
export function unitsOf(owner: unknown, field: FieldDescriptor, siblingField?: FieldDescriptor): string[] | null;
export function unitsFieldFor(owner: OutlineEntry, name: string): string | null;
export function plotRole(field: FieldDescriptor): "omit" | "hidden" | "show";
export function leaveOutOfPlot(field: FieldDescriptor): boolean;
export function typedNumericFields(value: unknown, d: TypeDescriptor | null | undefined, prefix?: string): Array<[string, number, boolean]>;
export function sensorTimestamp(value: unknown, d: TypeDescriptor | null | undefined): { seconds: number; path: string; type: string } | null;
export function deviceInfoRows(info: unknown, extraTypes?: string[]): Array<{ key: string; label: string; text: string }>;
/** The robdef type text a com.robotraconteur.datatype.DataType value stands for ("double[3]", "string{list}"); `descriptor` gives the device's enum values. */
export function formatDataType(value: unknown, descriptor?: TypeDescriptor | null): string | null;

// stdpanels-a (issue 54): wrenches, laser scans
/** "force (x, y, z) N, torque (x, y, z) N·m" of a com.robotraconteur.geometry.Wrench value, or null. */
export function formatWrench(value: unknown, digits?: number): string | null;
/** { torque: {x, y, z}, force: {x, y, z} } of a Wrench value (object or six numbers), or null. */
export function wrenchParts(value: unknown): { torque: { x: number; y: number; z: number }; force: { x: number; y: number; z: number } } | null;
/** A LaserScan's angles (radians) and ranges (metres). */
export function scanGeometry(scan: unknown): { angleMin: number; angleMax: number; angleIncrement: number; rangeMin: number; rangeMax: number; scanTime: number; count: number };
/** The returns of a LaserScan as points in metres (x forward, y left) and the index of each range. */
export function scanPoints(scan: unknown): { x: Float32Array; y: Float32Array; index: Uint32Array; n: number; maxRange: number };
/** [lo, hi] of a scan's finite intensities, or null. */
export function intensityRange(scan: unknown): [number, number] | null;
/** Draws a scan top-down into a 2D context; keep the returned reach and pass it back for a steady zoom. */
export function drawScan(g: CanvasRenderingContext2D | OffscreenCanvasRenderingContext2D, scan: unknown, width: number, height: number,
  options?: { reach?: number; background?: string }): { scale: number; reach: number; points: number; radius: number };
/** "541 ranges, -135° to 135° by 0.5°, 0.05 to 10 m". */
export function scanText(scan: unknown): string;
/** LaserScanPart packets back into whole scans. */
export class ScanAssembler {
  constructor(maxRanges?: number);
  dropped: number;
  stray: number;
  push(part: unknown): { scan_info: unknown; ranges: Float64Array; intensities: Float64Array | never[] } | null;
}

// stdpanels-c (issue 54): joint trajectories, PID gains, parameter infos
/** A JointTrajectory as plot series: joint names, times (s), positions per joint (radians as degrees), units. */
export function trajectorySeries(trajectory: unknown, unitEnum?: Array<{ name: string; value: number }> | null):
  { names: string[]; times: Float64Array; series: Float64Array[]; units: string[]; unitText: string[]; cut: boolean } | null;
/** "3 joints, 5 waypoints over 4.2 s (shoulder, elbow, wrist)". */
export function trajectoryText(trajectory: unknown, ctx?: object): string;
/** Draws trajectorySeries() as a plot (one line per joint, a legend) into a 2D context. */
export function drawTrajectory(g: CanvasRenderingContext2D | OffscreenCanvasRenderingContext2D,
  series: ReturnType<typeof trajectorySeries>, width: number, height: number): { min: number; max: number; t0: number; t1: number } | null;
/** "P 1.2, I 0.05, D 0.01; integral -5 … 5; command -10 … 10" of a com.robotraconteur.pid.PIDParam, or null. */
export function formatPid(value: unknown): string | null;
/** One line of a com.robotraconteur.param.ParameterInfo: name, type, units, description, default, range. */
export function formatParameterInfo(value: unknown, ctx?: { descriptor?: TypeDescriptor | null }): string | null;
/** A varvalue as short text ("1, 2", "\"text\""); "" for null. */
export function varText(value: unknown): string;
// stdpanels-d (issue 54): point clouds
/** A cloud's points as flat arrays: positions x, y, z per point (metres); intensity and packed rgb floats of PointCloud2 points, else null. */
export interface PackedCloud { count: number; positions: Float32Array; intensity: Float32Array | null; rgb: Float32Array | null }
/** A cloud ready to draw: finite points only, RGB bytes per point, bounds, the colour mode used and the span of the jet map (null for rgb). */
export interface DrawableCloud { count: number; positions: Float32Array; colors: Uint8Array; min: [number, number, number] | null; max: [number, number, number] | null; mode: "rgb" | "intensity" | "height"; range: [number, number] | null }
export const COLOR_MODES: readonly ["rgb", "intensity", "height"];
/** The whole (PointCloud, PointCloudf, PointCloud2, PointCloud2f) and part cloud types of com.robotraconteur.pointcloud. */
export const CLOUD_TYPES: readonly string[];
export const CLOUD_PART_TYPES: readonly string[];
/** The points of a PointCloud* value (points an Array of Point or PointCloud2Point objects) as flat arrays. */
export function packCloud(cloud: unknown): PackedCloud;
/** Holes dropped, bounds found, each point coloured by its rgb, intensity or height ("auto": the richest there is). */
export function colorCloud(packed: PackedCloud, options?: { mode?: "auto" | "rgb" | "intensity" | "height"; range?: [number, number] }): DrawableCloud;
/** The colour mode colorCloud uses for `packed` when `wanted` is asked for. */
export function colorModeFor(packed: PackedCloud, wanted?: string): "rgb" | "intensity" | "height";
/** [r, g, b] bytes of a PixelRGBFloatPacked float (its bits 0x00RRGGBB). */
export function unpackRgb(f: number): [number, number, number];
/** PointCloud*Part values back into whole packed clouds. */
export class CloudAssembler {
  constructor(maxPoints?: number);
  dropped: number;
  stray: number;
  push(part: unknown): (PackedCloud & { part: unknown }) | null;
}
/** "1.2 × 0.8 × 0.4 m at (0, 0, 0.2)" of a BoundingBox, or null. */
export function boundsText(box: unknown): string | null;
/** "20000 points, dense, 1.2 × 0.8 × 0.4 m at (0, 0, 0.2)". */
export function cloudText(cloud: unknown): string;
/** A drawable cloud projected from the front-left above onto a 2D context; returns the points drawn. */
export function drawCloud(g: CanvasRenderingContext2D | OffscreenCanvasRenderingContext2D, drawn: DrawableCloud, width: number, height: number,
  options?: { background?: string; pointSize?: number }): number;
/** Clouds made drawable in a Worker, the newest winning (one colouring, one waiting). */
export class CloudDecoder {
  constructor(options: { onResult: (result: (DrawableCloud & { ok: true; ms: number; packMs: number }) | { ok: false; error: { code: string; message: string } }, meta: Record<string, unknown> & { seq: number }) => void;
    Worker?: typeof Worker | null; workerUrl?: string | URL });
  readonly inWorker: boolean;
  stats: { submitted: number; decoded: number; failed: number; dropped: number };
  submit(input: { cloud: unknown } | { packed: PackedCloud }, options?: { mode?: string; range?: [number, number] }, meta?: Record<string, unknown>): void;
  dispose(): void;
}

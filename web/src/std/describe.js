// Type descriptors: a member's robdef type text resolved once, against the service definitions the
// device sent at run time (robdef_outline.js), into what the views need to show its values: the
// named type (through `using` and the service's own names), its kind (structure, pod, namedarray,
// enum), its fields as descriptors, and the renderer of the registry when the device's definition of
// the type has the field layout the renderer expects. A type the registry knows whose layout differs
// (an older release of the standard definitions, or a type of the same name that is something else)
// gets no renderer and a `mismatch` reason: the generic member view shows it.

import { parseType, NUMERIC_ARRAYS } from "./rr_types.js";

const PRIMITIVES = new Set([...Object.keys(NUMERIC_ARRAYS), "bool", "string", "varvalue", "varobject",
  "cdouble", "csingle", "void"]);

/** True for robdef's built-in type names ("double", "string", "varvalue", ...). */
export function isPrimitive(base) { return PRIMITIVES.has(base); }

/**
 * The declaration (outline entry, with `qualified` and `service`) that the name `name` means inside
 * service `scope`, resolved as robdef does: a qualified name as written, else a `using` alias of the
 * service, else a type of the service itself. Null when it does not resolve.
 */
export function resolveName(outline, name, scope) {
  if (!outline || !name || isPrimitive(name)) return null;
  if (name.includes(".")) return outline.types.get(name) || null;
  const home = outline.services.find((s) => s.name === scope);
  const used = home?.usings?.[name];
  if (used) return outline.types.get(used) || null;
  return outline.types.get(`${scope}.${name}`) || null;
}

/**
 * Like resolveName, and also looks in the services `scope` imports: for names that a definition
 * only implies (the enum of a flags field, which is typed as a plain integer), not for field types.
 */
export function findNamed(outline, name, scope) {
  const direct = resolveName(outline, name, scope);
  if (direct || !outline) return direct;
  const home = outline.services.find((s) => s.name === scope);
  for (const imported of home?.imports || []) {
    const t = outline.types.get(`${imported}.${name}`);
    if (t) return t;
  }
  return null;
}

/**
 * Type text with its named type fully qualified and spaces removed: "Point" in
 * com.robotraconteur.geometry → "com.robotraconteur.geometry.Point", "SIUnit{list}" →
 * "com.robotraconteur.units.SIUnit{list}". A name that does not resolve becomes "?Name".
 */
export function qualifyType(outline, text, scope) {
  const compact = String(text || "").replace(/\s+/g, "");
  const m = /^([A-Za-z_][\w.]*)(.*)$/.exec(compact);
  if (!m) return compact;
  if (isPrimitive(m[1])) return compact;
  const def = resolveName(outline, m[1], scope);
  return `${def ? def.qualified : `?${m[1]}`}${m[2]}`;
}

/**
 * Builds descriptors for one device's definitions and a renderer registry. Descriptors of named
 * types are made once and shared (recursive types included).
 */
export class TypeDescriber {
  /**
   * @param {import("./robdef_outline.js").RobdefOutline} outline  the device's definitions
   * @param {import("./registry.js").RendererRegistry} [registry]
   * @param {Array<(owner: object, field: {name: string, type: string, descriptor: object}, outline: object,
   *   fieldTypes: Map<string, object>) => object|null>} [annotators]
   *   field annotators: each may return properties to add to a field (flags: enum values of a bit-flag
   *   field, unitsField: the sibling field holding its units, ...). `field.descriptor` is the field's
   *   type descriptor, `fieldTypes` the descriptors of the owner's fields by name (empty for objects).
   */
  constructor(outline, registry = null, annotators = []) {
    this.outline = outline;
    this.registry = registry;
    this.annotators = annotators;
    this.named = new Map();
    this.layoutChecks = new Map();
  }

  /**
   * The descriptor of type text `text` written in service `scope`:
   * { text, qualifiedText, base, array, dims, container, kind, qualified, def, enumValues, renderer,
   *   mismatch, element, fields, generator, describeValueType }.
   * kind: "primitive", "struct", "pod", "namedarray", "enum", "object" or "unknown" (a name that does
   * not resolve). For arrays and containers (`array` or `container` set) `element` describes one item;
   * `fields` ([{ name, type, ...annotations }]) is there for structures, pods and namedarrays.
   * A generator's type ("double{generator}") is described by what it yields, with `generator: true`;
   * a varvalue's descriptor has describeValueType(text), which describes the type a value names.
   * Never throws: text it cannot read is a descriptor of kind "unknown".
   */
  describe(text, scope) {
    const raw = String(text ?? "");
    const yielded = raw.replace(/\{generator\}\s*$/, "");
    if (yielded !== raw) return { ...this.describe(yielded, scope), generator: true };
    const t = parseType(raw);
    const qualifiedText = qualifyType(this.outline, raw, scope);
    if (t.array || t.container) {
      // the outer level only: "double[]{list}" holds "double[]"
      const elementText = t.container ? raw.replace(/\{(int32|string|list)\}\s*$/, "") : raw.replace(/\[[^\]]*\]\s*$/, "");
      const element = this.describe(elementText, scope);
      return { ...t, qualifiedText, kind: element.kind, qualified: null, element };
    }
    if (t.base === "varvalue") {
      return { ...t, qualifiedText, kind: "primitive", qualified: null, describeValueType: (valueType) => this.describe(valueType, scope) };
    }
    if (isPrimitive(t.base)) return { ...t, qualifiedText, kind: "primitive", qualified: null };
    const def = resolveName(this.outline, t.base, scope);
    if (!def) return { ...t, qualifiedText, kind: "unknown", qualified: null };
    return this.describeNamed(def);
  }

  /** The field-like descriptor { name, type, params, ...annotations } of member `member` ({name, type,
   * params?} as the client package's $members give it) of object type `objectQualified`: its type
   * annotated as a field of the object would be, e.g. Camera's uint32 `capabilities` property with
   * its flags; `params` ([{name, type}]) the descriptors of a function's, event's or callback's
   * parameters. A generator function is described by the type it yields (`type.generator` true). */
  describeMember(objectQualified, member) {
    const owner = this.outline?.types.get(objectQualified);
    const scope = owner?.service ?? String(objectQualified).split(".").slice(0, -1).join(".");
    const type = this.describe(member.type, scope);
    const annotations = owner ? this.annotate(owner, { name: member.name, type: member.type, descriptor: type }, new Map()) : {};
    const params = (member.params || []).map((p) => ({ name: p.name, type: this.describe(p.type, scope) }));
    return { name: member.name, type, params, ...annotations };
  }

  describeNamed(def) {
    const cached = this.named.get(def.qualified);
    if (cached) return cached;
    const d = {
      ...parseType(def.qualified), qualifiedText: def.qualified, base: def.qualified, kind: def.kind,
      qualified: def.qualified, def, renderer: null, mismatch: null,
    };
    this.named.set(def.qualified, d);
    if (def.kind === "enum") d.enumValues = def.values;
    if (["struct", "pod", "namedarray"].includes(def.kind)) {
      const types = new Map(def.fields.map((f) => [f.name, this.describe(f.type, def.service)]));
      d.fields = def.fields.map((f) => ({
        name: f.name, type: types.get(f.name), ...this.annotate(def, { ...f, descriptor: types.get(f.name) }, types),
      }));
    }
    const renderer = this.registry?.get(def.qualified);
    if (renderer) {
      d.mismatch = this.layoutMismatch(def.qualified);
      if (!d.mismatch) d.renderer = renderer;
    }
    return d;
  }

  annotate(owner, field, fieldTypes) {
    const out = {};
    for (const a of this.annotators) Object.assign(out, a(owner, field, this.outline, fieldTypes) || {});
    return out;
  }

  /**
   * Why the device's definition of `qualified` does not have the layout its renderer expects (a
   * sentence), or null when it has it. Field types that are registered types are checked too.
   */
  layoutMismatch(qualified, seen = new Set()) {
    if (this.layoutChecks.has(qualified)) return this.layoutChecks.get(qualified);
    if (seen.has(qualified)) return null;
    seen.add(qualified);
    const layout = this.registry?.get(qualified)?.layout || {};
    const def = this.outline?.types.get(qualified);
    let why = null;
    if (!def) why = `${qualified} is not in the definitions`;
    for (const [name, expected] of Object.entries(layout)) {
      if (why) break;
      const field = def.fields?.find((f) => f.name === name);
      const accepted = [].concat(expected);
      if (!field) { why = `${qualified} has no field ${name}`; break; }
      const actual = qualifyType(this.outline, field.type, def.service);
      if (!accepted.includes(actual)) {
        why = `${qualified}.${name} is ${actual}, ${accepted.join(" or ")} expected`;
        break;
      }
      const base = parseType(actual).base;
      if (this.registry?.has(base)) {
        const inner = this.layoutMismatch(base, seen);
        if (inner) why = `${qualified}.${name}: ${inner}`;
      }
    }
    this.layoutChecks.set(qualified, why);
    return why;
  }
}

/** The field descriptor at dotted `path` ("image_info.encoding") under descriptor `d`, or null. */
export function fieldAt(d, path) {
  let field = null;
  for (const name of String(path).split(".")) {
    field = d?.fields?.find((f) => f.name === name) || null;
    if (!field) return null;
    d = field.type;
  }
  return field;
}

// What the value views of one device share, made once when its definitions arrive: its definitions
// (RobdefOutline), the type describer with the page's renderer registry (the standard one,
// std/standard.js, unless the page passed its own to the dashboard: dashboard.js), the enums the
// pictures and times need (ImageEncoding, ClockTypeCode) as the device itself defines them, and each
// member's descriptor, resolved once per member of each object.

import { TypeDescriber } from "../std/describe.js";
import { standardRegistry, STANDARD_ANNOTATORS } from "../std/standard.js";

const IMAGE_ENCODING = "com.robotraconteur.image.ImageEncoding";
const CLOCK_TYPE = "com.robotraconteur.datetime.ClockTypeCode";

/**
 * { outline, types, encodings, clockEnum, text, registry }: `types` the TypeDescriber, `text` the
 * context typedText and the renderers take ({ outline, encodings, clockEnum }).
 * @param {import("../std/robdef_outline.js").RobdefOutline} outline  the device's definitions
 * @param {object} [options]
 * @param {import("../std/registry.js").RendererRegistry} [options.registry]  the renderers (default: the standard ones)
 * @param {Array<Function>} [options.annotators]  field annotators (default: the standard ones)
 */
export function viewContext(outline, { registry = standardRegistry(), annotators = STANDARD_ANNOTATORS } = {}) {
  const enumValues = (q) => {
    const t = outline?.types?.get(q);
    return t?.kind === "enum" ? t.values : undefined;
  };
  const encodings = enumValues(IMAGE_ENCODING);
  const clockEnum = enumValues(CLOCK_TYPE);
  return {
    outline,
    registry,
    types: new TypeDescriber(outline, registry, annotators),
    encodings,
    clockEnum,
    text: { outline, encodings, clockEnum },
    members: new WeakMap(),  // a proxy's $members entry -> its descriptor
  };
}

/**
 * The descriptor of member `member` of object `obj` (TypeDescriber.describeMember: { name, type,
 * params, flags?, units? }), made once per member and kept; null without a view context.
 * Generator functions are described by the type they yield.
 */
export function describeMember(view, obj, member) {
  if (!view?.types) return null;
  const known = view.members?.get(member);
  if (known) return known;
  let d;
  try {
    d = view.types.describeMember(obj?.$type, member);
  } catch {
    // an annotator or renderer check that failed: the member still gets its plain descriptor
    d = new TypeDescriber(view.outline).describeMember(obj?.$type, member);
  }
  if (member && typeof member === "object") view.members?.set(member, d);
  return d;
}

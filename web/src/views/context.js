// What the value views of one device share, made once when its page is built: its definitions
// (RobdefOutline), the type describer with the standard renderers (std/standard.js), and the enums
// the pictures and times need (ImageEncoding, ClockTypeCode) as the device itself defines them.

import { standardDescriber } from "../std/standard.js";

const IMAGE_ENCODING = "com.robotraconteur.image.ImageEncoding";
const CLOCK_TYPE = "com.robotraconteur.datetime.ClockTypeCode";

/**
 * { outline, types, encodings, clockEnum, text }: `types` the TypeDescriber, `text` the context
 * typedText takes ({ outline }).
 */
export function viewContext(outline) {
  const enumValues = (q) => {
    const t = outline?.types?.get(q);
    return t?.kind === "enum" ? t.values : undefined;
  };
  return {
    outline,
    types: standardDescriber(outline),
    encodings: enumValues(IMAGE_ENCODING),
    clockEnum: enumValues(CLOCK_TYPE),
    text: { outline },
  };
}

/**
 * The descriptor of member `member` of object `obj` (describeMember: { name, type, flags?, units? }),
 * or null when it cannot be described. Generator functions are described by the type they yield.
 */
export function describeMember(view, obj, member) {
  if (!view?.types) return null;
  try {
    const type = String(member.type || "").replace(/\{generator\}\s*$/, "");
    return view.types.describeMember(obj?.$type, { name: member.name, type });
  } catch {
    return null;
  }
}

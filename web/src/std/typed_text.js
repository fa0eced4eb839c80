// Readable one-line text of a value typed by its descriptor (describe.js): registered renderers'
// text (UUIDs, identifiers, times, poses, images, ...), enums by name, flag fields by the names of
// their set flags, enum codes in integer fields by name, units after numbers whose structure names them; everything else as the generic
// view writes it (value_codec.js formatValue). Never throws: a renderer that fails gives the
// generic text.

import { formatValue } from "./value_text.js";
import { formatEnum, formatFlags, formatCodes } from "./enums.js";
import { unitsOf } from "./units.js";

/**
 * @param {any} value  as the client package gives it
 * @param {object} d  the value's type descriptor (TypeDescriber.describe)
 * @param {{now?: number, outline?: object}} [ctx]  passed to renderers (now: ms since the epoch)
 * @param {number} [maxItems]  items of a list shown before "… N more"
 */
export function typedText(value, d, ctx = {}, maxItems = 16) {
  if (value === null || value === undefined || !d) return formatValue(value, maxItems);
  if (d.renderer?.text && !d.array && !d.container) {
    try { return d.renderer.text(value, { ...ctx, descriptor: d }); } catch { return formatValue(value, maxItems); }
  }
  if (d.kind === "enum" && !d.array && !d.container && typeof value === "number") return formatEnum(d.enumValues, value);
  if ((d.array || d.container) && d.element && (d.element.kind !== "primitive" || d.element.array)) {
    return itemsText(value, d, ctx, maxItems);
  }
  if (d.fields && typeof value === "object" && !ArrayBuffer.isView(value) && !Array.isArray(value)) {
    return `{${d.fields.map((f) => `${f.name}: ${fieldText(value, f, d, ctx, maxItems)}`).join(", ")}}`;
  }
  return formatValue(value, maxItems);
}

/** Text of field `field` of structure value `owner` (described by `ownerDescriptor`). */
export function fieldText(owner, field, ownerDescriptor, ctx = {}, maxItems = 16) {
  const v = owner?.[field.name];
  let text;
  if (field.flags && (typeof v === "number" || typeof v === "bigint")) text = formatFlags(field.flags, v);
  else if (field.codes && (typeof v === "number" || typeof v === "bigint" || ArrayBuffer.isView(v) || Array.isArray(v))) {
    text = formatCodes(field.codes, v);
  }
  else text = typedText(v, field.type, ctx, maxItems);
  if (field.units) {
    const sibling = ownerDescriptor?.fields?.find((f) => f.name === field.units.field);
    const units = unitsOf(owner, field, sibling);
    if (units) text += new Set(units).size === 1 ? ` ${units[0]}` : ` (${units.join(", ")})`;
  }
  return text;
}

/** Text of a member's value, with the member's annotations (describeMember: e.g. Camera's
 * `capabilities` property as flag names). */
export function memberText(value, member, ctx = {}, maxItems = 16) {
  return fieldText({ [member.name]: value }, member, null, ctx, maxItems);
}

function itemsText(value, d, ctx, maxItems) {
  const element = d.element;
  if (value instanceof Map) {
    const entries = [...value].sort(([a], [b]) => (a < b ? -1 : a > b ? 1 : 0)).slice(0, maxItems);
    return `{${entries.map(([k, x]) => `${k}: ${typedText(x, element, ctx, maxItems)}`).join(", ")}}`;
  }
  if (d.container === "string" && typeof value === "object" && !Array.isArray(value)) {
    return `{${Object.entries(value).slice(0, maxItems).map(([k, x]) => `${k}: ${typedText(x, element, ctx, maxItems)}`).join(", ")}}`;
  }
  if (d.array === "multidim") return formatValue(value, maxItems);
  if (Array.isArray(value) || ArrayBuffer.isView(value)) {
    const items = Array.from(value.slice(0, maxItems), (x) => typedText(x, element, ctx, maxItems));
    const more = value.length > maxItems ? `, … ${value.length - maxItems} more` : "";
    return `[${items.join(", ")}${more}]`;
  }
  return formatValue(value, maxItems);
}

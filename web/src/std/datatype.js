// com.robotraconteur.datatype.DataType (a type as data: a parameter's type in a camera's param_info,
// a sensor's data type) as the robdef type text it stands for: "double", "uint8[3]", "string{list}",
// "com.robotraconteur.geometry.Pose[]", with its name after it when it has one ("double[] gains").
// The enum names come from the device's own DataTypeCode, ArrayTypeCode and ContainerTypeCode.

import { enumName } from "./enums.js";

const DT = "com.robotraconteur.datatype";
const CONTAINERS = { list_c: "{list}", map_int32_c: "{int32}", map_string_c: "{string}", generator_c: "{generator}" };

const enumOf = (d, field) => d?.fields?.find((f) => f.name === field)?.type?.enumValues;

/**
 * The type text of DataType value `v`; `d` its descriptor (for the device's enum values). Null for a
 * value that is not one.
 */
export function formatDataType(v, d) {
  if (!v || typeof v !== "object") return null;
  const code = enumName(enumOf(d, "type_code"), v.type_code);
  let base = typeof v.type_string === "string" && v.type_string ? v.type_string : code?.replace(/_c$/, "");
  if (!base) base = `type ${v.type_code}`;
  const lens = v.array_len ? Array.from(v.array_len, Number) : [];
  const array = enumName(enumOf(d, "array_type_code"), v.array_type_code);
  let dims = "";
  if (array === "array_c") dims = lens.length && lens[0] > 0 ? `[${lens[0]}${v.array_var_len ? "-" : ""}]` : "[]";
  else if (array === "multidimarray_c") dims = lens.length && !v.array_var_len ? `[${lens.join(",")}]` : "[*]";
  const container = CONTAINERS[enumName(enumOf(d, "container_type_code"), v.container_type_code)] ?? "";
  const name = typeof v.name === "string" && v.name ? ` ${v.name}` : "";
  return `${base}${dims}${container}${name}`;
}

export const renderers = [
  {
    type: `${DT}.DataType`,
    layout: {
      name: "string", type_code: `${DT}.DataTypeCode`, type_string: "string", array_type_code: `${DT}.ArrayTypeCode`,
      array_var_len: "bool", array_len: "uint32[]", container_type_code: `${DT}.ContainerTypeCode`,
    },
    text: (v, ctx) => formatDataType(v, ctx?.descriptor) ?? "null",
  },
];

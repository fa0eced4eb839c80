// com.robotraconteur.identifier.Identifier (struct: string name, UUID uuid) as "name (uuid)".

import { formatUuid, isNilUuid } from "./uuid.js";

/**
 * "name (8-4-4-4-12)"; just the name when the UUID is all zero; just the UUID when the name is
 * empty; "(none)" when both are empty (RR's "any" identifier); null for a value without name or uuid.
 */
export function formatIdentifier(v) {
  if (!v || typeof v !== "object" || !("name" in v || "uuid" in v)) return null;
  const name = typeof v.name === "string" ? v.name : "";
  const uuid = v.uuid && !isNilUuid(v.uuid) ? formatUuid(v.uuid) : null;
  if (name && uuid) return `${name} (${uuid})`;
  return name || uuid || "(none)";
}

export const renderers = [
  {
    type: "com.robotraconteur.identifier.Identifier",
    layout: { name: "string", uuid: "com.robotraconteur.uuid.UUID" },
    text: (v) => formatIdentifier(v) ?? "null",
  },
];

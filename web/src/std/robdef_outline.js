// An outline of service definition texts (robdef §Service definition): the named types each service
// declares (struct, pod, namedarray, enum, object) with their fields, enum values and member lines,
// with line numbers for the definition browser. The client package has checked the texts already;
// this reads only what the page needs to build editors and links.

const BLOCK = /^(struct|pod|namedarray|object|enum)\s+([A-Za-z_]\w*)/;

/**
 * Parses one definition text. Returns { name, imports, usings: { alias: qualified },
 * entries: [{ kind, name, line, fields, values, members }] }.
 */
export function outlineDefinition(text) {
  const service = { name: "", imports: [], usings: {}, entries: [] };
  let current = null;
  String(text).split(/\r?\n/).forEach((raw, i) => {
    const line = raw.replace(/#.*$/, "").trim();
    if (!line) return;
    const words = line.split(/\s+/);
    if (!current) {
      if (words[0] === "service") service.name = words[1] || "";
      else if (words[0] === "import") service.imports.push(words[1]);
      else if (words[0] === "using" && words[1]) {
        // "using a.b.C" or "using a.b.C as D": C (or D) names a.b.C in this service
        service.usings[words[2] === "as" && words[3] ? words[3] : words[1].split(".").pop()] = words[1];
      }
      const m = BLOCK.exec(line);
      if (m) {
        current = { kind: m[1], name: m[2], line: i + 1, fields: [], values: [], members: [] };
        service.entries.push(current);
      }
      return;
    }
    if (words[0] === "end") { current = null; return; }
    if (current.kind === "enum") {
      for (const part of line.split(",")) {
        const [name, value] = part.split("=").map((s) => s.trim());
        if (!name) continue;
        const prev = current.values.length ? current.values[current.values.length - 1].value : -1;
        current.values.push({ name, value: value !== undefined ? Number(value) : prev + 1 });
      }
    } else if (words[0] === "field") {
      current.fields.push({ type: words.slice(1, -1).join(" "), name: words[words.length - 1], line: i + 1 });
    } else {
      current.members.push({ kind: words[0], text: line, line: i + 1 });
    }
  });
  return service;
}

/** All definitions of a device: type lookup across services, as the robdef resolves names. */
export class RobdefOutline {
  /** @param {Record<string,string>} definitions  { "<service name>": "<robdef text>" } */
  constructor(definitions) {
    this.services = Object.entries(definitions || {}).map(([name, text]) => {
      const s = outlineDefinition(text);
      return { ...s, name: s.name || name, text };
    });
    this.types = new Map();
    for (const s of this.services) {
      for (const e of s.entries) this.types.set(`${s.name}.${e.name}`, { ...e, service: s.name, qualified: `${s.name}.${e.name}` });
    }
  }

  /** The named type `name` ("SensorPacket" or "experimental.create.SensorPacket") seen from service `scope`. */
  typeOf(name, scope) {
    if (!name) return null;
    if (this.types.has(name)) return this.types.get(name);
    const order = [];
    const home = this.services.find((s) => s.name === scope);
    if (home?.usings[name] && this.types.has(home.usings[name])) return this.types.get(home.usings[name]);
    if (home) order.push(home.name, ...home.imports);
    order.push(...this.services.map((s) => s.name));
    for (const s of order) {
      const t = this.types.get(`${s}.${name}`);
      if (t) return t;
    }
    return null;
  }

  /** Enum values [{name, value}] of `name`, or null when it is not an enum. */
  enumOf(name, scope) {
    const t = this.typeOf(name, scope);
    return t && t.kind === "enum" ? t.values : null;
  }

  /** The service that declares object type `qualified` ("experimental.create.Create"). */
  serviceOfObject(qualified) {
    const t = this.types.get(qualified);
    return t ? t.service : (String(qualified).split(".").slice(0, -1).join(".") || null);
  }
}

// The panel registry: panels of an RR object chosen from the object types it implements
// (`$type` and `$implements` as the device's definitions declare them), e.g. a camera panel for
// com.robotraconteur.imaging.Camera, a device card for com.robotraconteur.device.Device. It knows no
// panel itself: panels/standard.js registers the standard ones. A panel may also claim objects by
// their members (`applies`), for devices that carry a standard member without declaring the type.

/**
 * @typedef {object} PanelEntry
 * @property {string} name  short id ("device-card", "camera")
 * @property {string[]} [types]  fully qualified object types the panel is for
 * @property {(obj: object, view: object) => boolean} [applies]  also (or instead) by the object's members
 * @property {(parent: HTMLElement, ctx: object) => {el: HTMLElement, dispose(): void}} create
 * @property {number} [order]  lower first (default 100)
 */

/** The object types of a proxy: its own and those it implements (qualified names). */
export function objectTypes(obj) {
  const out = new Set();
  if (obj?.$type) out.add(obj.$type);
  for (const t of obj?.$implements || []) out.add(t);
  return out;
}

export class PanelRegistry {
  constructor() {
    /** @type {PanelEntry[]} */
    this.entries = [];
  }

  /** Adds panels; each needs a name and create(), and types or applies. Returns this. */
  register(...entries) {
    for (const e of entries.flat()) {
      if (!e || typeof e.name !== "string" || typeof e.create !== "function" || (!e.types?.length && typeof e.applies !== "function")) {
        throw new Error("a panel needs a name, create(), and types or applies()");
      }
      this.entries = this.entries.filter((x) => x.name !== e.name).concat(e);
    }
    return this;
  }

  /**
   * The panels for object proxy `obj`, in order: those registered for one of its types, and those
   * whose applies(obj, view) is true. A throwing applies() counts as false.
   */
  panelsFor(obj, view) {
    const types = objectTypes(obj);
    return this.entries.filter((e) => {
      if (e.types?.some((t) => types.has(t))) return true;
      if (typeof e.applies !== "function") return false;
      try { return !!e.applies(obj, view); } catch { return false; }
    }).sort((a, b) => (a.order ?? 100) - (b.order ?? 100));
  }
}

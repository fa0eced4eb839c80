// The renderer registry: renderers of Robot Raconteur structure, pod and namedarray types, keyed by
// fully qualified type name ("com.robotraconteur.image.Image"). It knows no type itself: modules
// register what they render (standard.js gathers the standard ones). A renderer is used for a value
// only when the device's own definition of the type has the field layout the renderer expects
// (describe.js checks it); otherwise the generic member view shows the value.

/**
 * @typedef {object} Renderer
 * @property {string} type  fully qualified type name
 * @property {Record<string, string|string[]>} [layout]  the fields the renderer reads: name → type
 *   text (primitives as robdef writes them, named types fully qualified); an array lists accepted
 *   alternatives. Fields the device has beyond these are allowed.
 * @property {(value: any, ctx: object) => string} [text]  one line of readable text for a value
 * @property {(value: any, ctx: object) => object} [image]  a decoded picture ({ok, width, height, data}
 *   or {ok: false, error}); see image_decode.js
 */

export class RendererRegistry {
  constructor() {
    /** @type {Map<string, Renderer>} */
    this.byType = new Map();
  }

  /** Adds (or replaces) renderers; each needs `type`. Returns this. */
  register(...renderers) {
    for (const r of renderers.flat()) {
      if (!r || typeof r.type !== "string" || !r.type.includes(".")) {
        throw new Error("a renderer needs a fully qualified type name");
      }
      this.byType.set(r.type, r);
    }
    return this;
  }

  /** The renderer registered for `qualified`, or null. */
  get(qualified) { return this.byType.get(qualified) || null; }

  has(qualified) { return this.byType.has(qualified); }

  /** The registered type names. */
  types() { return [...this.byType.keys()]; }
}

// The service definitions of a device as text, with keywords marked and every named type a link to
// the line that declares it (also from the member cards, through linkType()).

import { h } from "./dom.js";

const KEYWORDS = new Set(["service", "stdver", "import", "using", "struct", "pod", "namedarray", "enum",
  "object", "end", "field", "property", "function", "event", "objref", "pipe", "callback", "wire", "memory",
  "constant", "exception", "implements", "option"]);

export class DefinitionView {
  /** @param {HTMLElement} parent @param {import("./std/robdef_outline.js").RobdefOutline} outline */
  constructor(parent, outline, idPrefix) {
    this.outline = outline;
    this.idPrefix = idPrefix;
    this.el = h("div", { class: "definitions" });
    for (const s of outline.services) {
      const pre = h("pre", { class: "robdef" });
      s.text.split(/\r?\n/).forEach((line, i) => pre.append(this.line(s, line, i + 1)));
      this.el.append(h("details", { open: true, dataset: { service: s.name } }, h("summary", { text: s.name }), pre));
    }
    parent.append(this.el);
  }

  anchor(qualified) { return `${this.idPrefix}-${qualified.replace(/[^\w]/g, "_")}`; }

  line(service, text, number) {
    const el = h("div", { class: "robdef-line" });
    const declared = service.entries.find((e) => e.line === number);
    if (declared) el.id = this.anchor(`${service.name}.${declared.name}`);
    const hash = text.indexOf("#");
    const code = hash >= 0 ? text.slice(0, hash) : text;
    for (const token of code.split(/([^\w.]+)/)) {
      if (!token) continue;
      if (KEYWORDS.has(token)) el.append(h("span", { class: "kw", text: token }));
      else if (/^[A-Za-z_]/.test(token) && (!declared || token !== declared.name) && this.outline.typeOf(token, service.name)) {
        el.append(this.link(token, service.name));
      } else el.append(token);
    }
    if (hash >= 0) el.append(h("span", { class: "comment", text: text.slice(hash) }));
    return el;
  }

  /** A link to the declaration of named type `name` seen from `scope`, or null if it is not declared. */
  link(name, scope) {
    const t = this.outline.typeOf(name, scope);
    if (!t) return null;
    return h("a", {
      href: "#", class: "type-link", title: t.qualified, text: name, onclick: (ev) => {
        ev.preventDefault();
        const target = document.getElementById(this.anchor(t.qualified));
        if (!target) return;
        target.closest("details").open = true;
        target.scrollIntoView({ block: "center" });
        target.classList.remove("flash");
        void target.offsetWidth;
        target.classList.add("flash");
      },
    });
  }
}

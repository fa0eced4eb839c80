// The device's event log: RR events, callback calls, and session changes, newest first.

import { h, clockText } from "./dom.js";

export class EventLog {
  /** @param {HTMLElement} parent @param {number} maxEntries  older entries are dropped */
  constructor(parent, maxEntries = 200) {
    this.maxEntries = maxEntries;
    this.list = h("ol", { class: "event-log", reversed: true, "aria-live": "polite" });
    this.clearButton = h("button", { type: "button", class: "small", text: "Clear", onclick: () => this.list.replaceChildren() });
    parent.append(h("div", { class: "section-tools" }, this.clearButton), this.list);
  }

  /**
   * Adds an entry. kind: "event" | "callback" | "session" | "error"; member: the member name (or "");
   * text: what happened.
   */
  add(kind, member, text) {
    const item = h("li", { class: `log-${kind}`, dataset: { kind, member } },
      h("time", { text: clockText() }), h("span", { class: "log-member", text: member }),
      h("span", { class: "log-text", text }));
    this.list.prepend(item);
    while (this.list.children.length > this.maxEntries) this.list.lastElementChild.remove();
  }
}

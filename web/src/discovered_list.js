// The nodes and services the gateway's discovery found (GET api/discovered, docs/json-api.md
// "Discovery"), polled every 2 s below the device list: network (udp), this computer's rr+local nodes
// (local) and USB boards (usb). A service no gateway device serves yet has an "Add" button that turns it
// into a device for this run (POST api/discovered/add); the device list then shows it. The page starts
// it only when GET api/features says discovery is on; should api/discovered answer 404 anyway (turned
// off since), the section hides and polling stops. USB boards the gateway cannot use are listed with
// the reason (e.g. the udev rule to install).

import { h, errorText } from "./dom.js";

const POLL_MS = 2000;

/**
 * The view model of a GET api/discovered answer: nodes sorted by NodeName then NodeID, each with its
 * services sorted by name; `canAdd` when no gateway device serves the service yet. Malformed entries
 * are skipped (the page never throws on what the server sends).
 */
export function discoveredModel(data) {
  const nodes = [];
  for (const n of Array.isArray(data?.nodes) ? data.nodes : []) {
    if (!n || typeof n.nodeid !== "string") continue;
    const services = [];
    for (const s of Array.isArray(n.services) ? n.services : []) {
      if (!s || typeof s.name !== "string") continue;
      const device = typeof s.device === "string" ? s.device : null;
      services.push({ name: s.name, type: String(s.root_object_type ?? ""), device, canAdd: device === null });
    }
    services.sort((a, b) => a.name.localeCompare(b.name));
    nodes.push({
      nodeid: n.nodeid,
      nodename: typeof n.nodename === "string" ? n.nodename : "",
      source: typeof n.source === "string" ? n.source : "",
      urls: Array.isArray(n.urls) ? n.urls.map(String) : [],
      known: Array.isArray(n.services),  // false: its service index has not answered (yet)
      error: typeof n.error === "string" && n.error ? n.error : null,
      services,
    });
  }
  nodes.sort((a, b) => (a.nodename || "\uffff").localeCompare(b.nodename || "\uffff") || a.nodeid.localeCompare(b.nodeid));
  const problems = (Array.isArray(data?.usb_problems) ? data.usb_problems : [])
    .filter((p) => p && typeof p.error === "string")
    .map((p) => ({ device: String(p.device ?? ""), path: String(p.path ?? ""), error: p.error }));
  return { nodes, problems };
}

/** The body of POST api/discovered/add for a service of a node (`name` omitted: the service name, made unique). */
export function addRequest(nodeid, service) {
  return { nodeid, service };
}

export class DiscoveredList extends EventTarget {
  /** `nav`: the element to append the section to. Events: "added" with detail = the new device. */
  constructor(nav) {
    super();
    this.section = h("section", { class: "discovered", hidden: true, "aria-label": "Discovered" });
    this.list = h("ul", { class: "discovered-nodes" });
    this.problems = h("ul", { class: "usb-problems" });
    this.status = h("p", { class: "discovered-status hint" });
    this.section.append(h("h2", { text: "Discovered" }), this.status, this.list, this.problems);
    nav.append(this.section);
    this.pending = new Map();  // "nodeid/service" -> error text or "" while adding
  }

  start() {
    this.poll();
    this.timer = setInterval(() => this.poll(), POLL_MS);
  }

  stop() {
    clearInterval(this.timer);
    this.timer = undefined;
  }

  async poll() {
    try {
      const r = await fetch("api/discovered", { headers: { Accept: "application/json" }, cache: "no-store" });
      if (r.status === 404) {
        this.section.hidden = true;  // discovery is off: nothing to ask again
        this.stop();
        return;
      }
      if (!r.ok) throw new Error(`GET api/discovered: HTTP ${r.status}`);
      this.model = discoveredModel(await r.json());
      this.status.textContent = "";
      this.section.hidden = false;
      // Rebuilt only when something changed (a button under the pointer stays the same element).
      const key = JSON.stringify([this.model, [...this.pending]]);
      if (key !== this.shown) this.render();
    } catch (e) {
      this.status.textContent = `discovery unavailable: ${errorText(e)}`;
    }
  }

  async add(nodeid, service) {
    const key = `${nodeid}/${service}`;
    this.pending.set(key, "");
    this.render();
    try {
      const r = await fetch("api/discovered/add", {
        method: "POST",
        headers: { "Content-Type": "application/json", Accept: "application/json" },
        body: JSON.stringify(addRequest(nodeid, service)),
      });
      const body = await r.json().catch(() => null);
      if (!r.ok) throw new Error(body?.error ? `${body.error.name}: ${body.error.message}` : `HTTP ${r.status}`);
      this.pending.delete(key);
      this.dispatchEvent(new CustomEvent("added", { detail: body }));
      await this.poll();
    } catch (e) {
      this.pending.set(key, errorText(e));
      this.render();
    }
  }

  render() {
    if (!this.model) return;
    this.shown = JSON.stringify([this.model, [...this.pending]]);
    const items = this.model.nodes.map((n) => h("li", { class: "discovered-node", dataset: { nodeid: n.nodeid, source: n.source } },
      h("div", { class: "discovered-head" },
        h("span", { class: "device-name", text: n.nodename || n.nodeid }),
        h("span", { class: "badge", text: n.source })),
      h("span", { class: "device-type", text: n.urls[0] || "" }),
      n.error ? h("span", { class: "device-reason", text: n.error }) : null,
      !n.known && !n.error ? h("span", { class: "hint", text: "asking for its services…" }) : null,
      h("ul", { class: "discovered-services" }, n.services.map((s) => {
        const key = `${n.nodeid}/${s.name}`;
        const state = this.pending.get(key);
        return h("li", { dataset: { service: s.name } },
          h("span", { class: "service-name", text: s.name }),
          h("span", { class: "device-type", text: s.type }),
          s.canAdd
            ? h("button", { type: "button", class: "add", disabled: state === "", onclick: () => this.add(n.nodeid, s.name), text: state === "" ? "Adding…" : "Add" })
            : h("a", { class: "served-by", href: `#/${encodeURIComponent(s.device)}`, text: `device ${s.device}` }),
          state ? h("span", { class: "device-reason", text: state }) : null);
      }))));
    this.list.replaceChildren(...items);
    if (!items.length) this.list.append(h("li", { class: "hint", text: "No nodes found yet." }));
    this.problems.replaceChildren(...this.model.problems.map((p) =>
      h("li", { class: "device-reason", text: `USB ${p.device} (${p.path}): ${p.error}` })));
  }
}

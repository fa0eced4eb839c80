// The gateway's devices and their live connection state, from GET api/devices (docs/json-api.md),
// polled every second. Events (EventTarget): "update" with detail = the device array, "error".

import { h, errorText } from "./dom.js";

const POLL_MS = 1000;

/** Locks the gateway knows on a device's objects: held at it (shared) or taken through it (passthrough); docs/security.md. */
export function lockLines(d) {
  if (!Array.isArray(d.locks)) return [];
  return d.locks.map((l) => h("span", {
    class: "device-lock",
    dataset: { kind: l.kind },
    text: `${l.kind === "monitor" ? "monitor" : `${l.kind} lock`} on ${l.path} by ${l.user ?? "an anonymous client"}`,
  }));
}

export class DeviceList extends EventTarget {
  constructor(nav, statusEl) {
    super();
    this.nav = nav;
    this.statusEl = statusEl;
    this.devices = [];
    this.selected = null;
    this.list = h("ul", { class: "devices" });
    nav.append(h("h2", { text: "Devices" }), this.list);
  }

  start() {
    this.poll();
    this.timer = setInterval(() => this.poll(), POLL_MS);
  }

  device(name) { return this.devices.find((d) => d.name === name) || null; }

  async poll() {
    try {
      const r = await fetch("api/devices", { headers: { Accept: "application/json" }, cache: "no-store" });
      // The gateway has users (docs/security.md) and this browser is not logged in, or its session ended.
      if (r.status === 401) {
        location.replace("login.html");
        return;
      }
      if (!r.ok) throw new Error(`GET api/devices: HTTP ${r.status}`);
      this.devices = await r.json();
      this.setGatewayStatus("connected", "gateway connected");
      const key = JSON.stringify(this.devices);
      if (key !== this.shown) this.render();
      this.shown = key;
      this.dispatchEvent(new CustomEvent("update", { detail: this.devices }));
    } catch (e) {
      this.setGatewayStatus("failed", `gateway unreachable: ${errorText(e)}`);
      this.dispatchEvent(new CustomEvent("error", { detail: e }));
    }
  }

  setGatewayStatus(state, text) {
    this.statusEl.dataset.state = state;
    this.statusEl.textContent = text;
  }

  setSelected(name) {
    this.selected = name;
    for (const li of this.list.children) li.classList.toggle("selected", li.dataset.device === name);
  }

  render() {
    const items = this.devices.map((d) => h("li", { dataset: { device: d.name, state: d.state }, class: d.name === this.selected ? "selected" : null },
      h("a", { href: `#/${encodeURIComponent(d.name)}` },
        h("span", { class: "device-name", text: d.name }),
        h("span", { class: "badge", dataset: { state: d.state }, text: d.state }),
        h("span", { class: "device-type", text: d.object_type || d.url }),
        d.reason && d.state !== "connected" ? h("span", { class: "device-reason", text: d.reason }) : null,
        h("span", { class: "device-clients", text: `${d.clients} client${d.clients === 1 ? "" : "s"}` }),
        ...lockLines(d))));
    this.list.replaceChildren(...items);
    if (!items.length) this.list.append(h("li", { class: "hint", text: "No devices configured." }));
  }
}

// The page of one device: its state at the gateway (from the device list) and of this page's own RR
// session, the members of its root object, the event log and the service definitions. The members are
// rebuilt on every (re)connect and whenever the gateway reports the device back after a drop, so
// subscriptions, pipe endpoints and open objects start fresh; what was open is remembered.

import { h, errorText } from "./dom.js";
import { DeviceSession, deviceUrl } from "./device_session.js";
import { RobdefOutline } from "./robdef_outline.js";
import { DefinitionView } from "./definition_view.js";
import { ObjectPanel } from "./object_panel.js";
import { EventLog } from "./event_log.js";

export class DeviceView {
  constructor(root, name, list) {
    this.name = name;
    this.list = list;
    this.memory = new Map();
    this.panel = null;
    this.client = null;
    this.gatewayBadge = h("span", { class: "badge", dataset: { state: "connecting" }, text: "…" });
    this.sessionBadge = h("span", { class: "badge", dataset: { state: "connecting" }, text: "connecting" });
    this.typeEl = h("code", { class: "object-type" });
    this.banner = h("div", { class: "device-error", role: "alert", hidden: true });
    this.members = h("div", { class: "device-members" });
    const logBox = h("section", { class: "side-section event-section" }, h("h3", { text: "Event log" }));
    this.defBox = h("section", { class: "side-section definition-section" }, h("h3", { text: "Service definition" }));
    this.el = h("div", { class: "device-view", dataset: { device: name } },
      h("header", { class: "device-header" },
        h("h2", { text: name }), this.typeEl,
        h("span", { class: "state-label", text: "gateway → device" }), this.gatewayBadge,
        h("span", { class: "state-label", text: "this page → gateway" }), this.sessionBadge),
      this.banner,
      h("div", { class: "device-body" }, this.members, h("aside", { class: "device-side" }, logBox, this.defBox)));
    root.append(this.el);
    this.log = new EventLog(logBox);

    this.onDevices = () => this.deviceUpdate(list.device(name));
    list.addEventListener("update", this.onDevices);
    this.deviceUpdate(list.device(name));

    this.session = new DeviceSession(deviceUrl(name));
    this.session.addEventListener("state", (ev) => this.sessionUpdate(ev.detail));
    this.session.start();
  }

  showBanner(text) {
    this.banner.textContent = text || "";
    this.banner.hidden = !text;
  }

  deviceUpdate(d) {
    const state = d ? d.state : "unknown";
    const before = this.gatewayState;
    this.gatewayState = state;
    this.gatewayBadge.dataset.state = state;
    this.gatewayBadge.textContent = state;
    if (d?.object_type) this.typeEl.textContent = d.object_type;
    if (before === undefined || before === state) return;
    this.log.add("session", "", `device ${state}${d?.reason && state !== "connected" ? `: ${d.reason}` : ""}`);
    if (state !== "connected") {
      const what = state === "connecting" ? "The gateway is connecting to the device" : `Device ${state}`;
      this.showBanner(`${what}${d?.reason ? `: ${d.reason}` : ""}. The gateway keeps reconnecting; this page follows.`);
    } else {
      this.showBanner("");
      if (this.client) this.render(this.client);
      else this.session.retryNow();
    }
  }

  sessionUpdate({ state, client, error, attempt }) {
    this.sessionBadge.dataset.state = state;
    this.sessionBadge.textContent = state === "connecting" && attempt > 1 ? `reconnecting (${attempt})` : state;
    if (state === "connected") {
      this.client = client;
      this.showBanner("");
      this.log.add("session", "", `connected to ${this.session.url}`);
      this.render(client);
    } else if (state === "closed") {
      this.client = null;
      this.clear();
      this.showBanner(`No RR session to ${this.session.url}: ${errorText(error)}`);
      this.log.add("error", "", errorText(error));
    }
  }

  clear() {
    this.panel?.dispose();
    this.panel = null;
    this.definitions?.el.remove();
    this.definitions = null;
  }

  render(client) {
    this.clear();
    const outline = new RobdefOutline(client.$definitions);
    this.definitions = new DefinitionView(this.defBox, outline, `def-${this.name}`);
    this.typeEl.textContent = client.$type;
    this.panel = new ObjectPanel(this.members, {
      obj: client, outline, definitions: this.definitions, log: this.log, memory: this.memory, path: "",
    });
  }

  close() {
    this.list.removeEventListener("update", this.onDevices);
    this.session.stop();
    this.clear();
    this.el.remove();
  }
}

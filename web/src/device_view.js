// The page of one device: its state at the gateway (from the device list) and of this page's own RR
// session, the members of its root object, the event log and the service definitions. The members are
// rebuilt on every (re)connect and whenever the gateway reports the device back after a drop, so
// subscriptions, pipe endpoints and open objects start fresh; what was open is remembered.
//
// A device that refuses the session with AuthenticationError (its own logins, through an `auth:
// passthrough` gateway device) gets a login form instead of retries; the page then connects with the
// user's credentials, and "Log out of device" closes that session and shows the form again.

import { h, errorText } from "./dom.js";
import { DeviceSession, deviceUrl } from "./device_session.js";
import { RobdefOutline } from "./std/robdef_outline.js";
import { DefinitionView } from "./definition_view.js";
import { ObjectPanel } from "./object_panel.js";
import { EventLog } from "./event_log.js";
import { viewContext } from "./views/context.js";
import { LiveObject } from "./views/live_object.js";
import { standardPanels } from "./panels/standard.js";
import { RecordControl } from "./record/record_control.js";
import { ReplayTimeline } from "./record/replay_timeline.js";
import { listReplays } from "./record/recording_api.js";
import { fetchAccess } from "./robot/access.js";

// The panels chosen by object type (panels/standard.js) and the renderers of value types
// (std/standard.js) unless the page gave its own (dashboard.js startDashboard).
const STANDARD_PANELS = standardPanels();

// Device logins of this page, by device name: kept in memory only (never in localStorage,
// sessionStorage or cookies), so that switching between devices does not ask again; a reload forgets them.
const deviceLogins = new Map();

export class DeviceView {
  /**
   * @param {HTMLElement} root
   * @param {string} name  the device's name at the gateway
   * @param {import("./device_list.js").DeviceList} list
   * @param {object} [options]  panels: a PanelRegistry (panels/registry.js), renderers: a
   *   RendererRegistry (std/registry.js); the standard ones by default
   */
  constructor(root, name, list, { panels = STANDARD_PANELS, renderers = undefined } = {}) {
    this.name = name;
    this.list = list;
    this.panels = panels;
    this.renderers = renderers;
    this.memory = new Map();
    this.panel = null;
    this.client = null;
    this.gatewayBadge = h("span", { class: "badge", dataset: { state: "connecting" }, text: "…" });
    this.sessionBadge = h("span", { class: "badge", dataset: { state: "connecting" }, text: "connecting" });
    this.typeEl = h("code", { class: "object-type" });
    this.banner = h("div", { class: "device-error", role: "alert", hidden: true });
    this.loginForm = this.makeLoginForm();
    this.userName = h("span", { class: "device-user-name" });
    this.userBox = h("span", { class: "device-user", hidden: true },
      h("span", { class: "state-label", text: "device user" }), this.userName,
      h("button", { type: "button", class: "small device-logout", text: "Log out of device", onclick: () => this.logout() }));
    this.members = h("div", { class: "device-members" });
    // the replay timeline (a replayed device) and the Record control, above the members
    this.tools = h("div", { class: "device-tools" });
    const logBox = h("section", { class: "side-section event-section" }, h("h3", { text: "Event log" }));
    this.defBox = h("section", { class: "side-section definition-section" }, h("h3", { text: "Service definition" }));
    this.el = h("div", { class: "device-view", dataset: { device: name } },
      h("header", { class: "device-header" },
        h("h2", { text: name }), this.typeEl,
        h("span", { class: "state-label", text: "gateway → device" }), this.gatewayBadge,
        h("span", { class: "state-label", text: "this page → gateway" }), this.sessionBadge, this.userBox),
      this.banner,
      h("div", { class: "device-body" }, h("div", { class: "device-main" }, this.loginForm.el, this.tools, this.members), h("aside", { class: "device-side" }, logBox, this.defBox)));
    root.append(this.el);
    this.log = new EventLog(logBox);

    this.onDevices = () => this.deviceUpdate(list.device(name));
    list.addEventListener("update", this.onDevices);
    this.deviceUpdate(list.device(name));

    this.session = new DeviceSession(deviceUrl(name), { credentials: deviceLogins.get(name) ?? null });
    this.session.addEventListener("state", (ev) => this.sessionUpdate(ev.detail));
    this.session.start();
    this.showReplay();
  }

  /**
   * A device replayed from a file (listed by GET api/replays) gets its timeline; the controls need
   * write on the device (api/devices/<name>/access), as POST api/replays/<name> does.
   */
  async showReplay() {
    try {
      const status = (await listReplays()).replays?.find((r) => r.name === this.name);
      if (!status || this.closed) return;
      const mayControl = await this.mayWriteDevice();
      if (this.closed) return;
      this.replay = new ReplayTimeline(this.tools, { name: this.name, status, mayControl });
      this.tools.prepend(this.replay.el);
      // the Record control (made when the device connects, before or after this) says it records a replay
      this.replayFile = status.file;
      this.recorder?.markReplay(status.file);
    } catch (e) {
      this.log.add("error", "", `replay status: ${errorText(e)}`);
    }
  }

  /**
   * Whether this login may write the whole device (write on every member), which replay control
   * needs (POST api/replays/<name>: docs/security.md). Asked once per page.
   * @returns {Promise<boolean>}
   */
  mayWriteDevice() {
    this.writeAccess ??= fetchAccess(this.name).then(
      (access) => access.members === null ||
        (Object.keys(access.members).length > 0 && Object.values(access.members).every((ops) => Array.isArray(ops) && ops.includes("write"))),
      () => false);
    return this.writeAccess;
  }

  /**
   * Whether this login has the `record` right on the device (POST api/recordings: docs/recording.md);
   * true without logins. Asked once per page.
   * @returns {Promise<boolean>}
   */
  mayRecordDevice() {
    this.recordAccess ??= fetchAccess(this.name).then((access) => access.members === null || access.record === true, () => false);
    return this.recordAccess;
  }

  /** The form asking for the device's own login: user, password, "Log in", the device's error. */
  makeLoginForm() {
    const username = h("input", { name: "username", autocomplete: "username", required: true });
    const password = h("input", { name: "password", type: "password", autocomplete: "current-password", required: true });
    const submit = h("button", { type: "submit", class: "device-login-submit", text: "Log in" });
    const error = h("p", { class: "device-login-error", role: "alert", hidden: true });
    const el = h("form", { class: "device-login", hidden: true, onsubmit: (ev) => {
      ev.preventDefault();
      submit.disabled = true;
      error.hidden = true;
      this.session.login(username.value, password.value);
    } },
    h("h3", { text: `Log in to ${this.name}` }),
    h("p", { class: "hint", text: "This device has logins of its own; the gateway passes yours on to it. Kept in this page's memory only." }),
    h("label", {}, h("span", { text: "User" }), username),
    h("label", {}, h("span", { text: "Password" }), password),
    submit, error);
    return { el, username, password, submit, error };
  }

  /** Shows the login form with the device's refusal (none after a logout). */
  showLogin(error) {
    const f = this.loginForm;
    f.el.hidden = false;
    f.submit.disabled = false;
    f.error.textContent = error ? errorText(error) : "";
    f.error.hidden = !error;
    f.password.value = "";
    if (!f.username.value && this.session.username) f.username.value = this.session.username;
    (f.username.value ? f.password : f.username).focus();
  }

  logout() {
    deviceLogins.delete(this.name);
    this.log.add("session", "", `logged out of ${this.name}`);
    this.session.logout();
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
    // The form stays up while its login connects; any other state takes it away.
    if (state !== "login" && state !== "connecting") this.loginForm.el.hidden = true;
    this.userBox.hidden = !(state === "connected" && this.session.username);
    if (state === "login") {
      this.client = null;
      this.clear();
      this.showBanner("");
      this.sessionBadge.textContent = "login required";
      deviceLogins.delete(this.name);
      this.showLogin(error);
      if (error) this.log.add("error", "", errorText(error));
      return;
    }
    if (state === "connected") {
      this.client = client;
      if (this.session.username) deviceLogins.set(this.name, this.session.credentials);
      this.userName.textContent = this.session.username ?? "";
      this.showBanner("");
      this.log.add("session", "", `connected to ${this.session.url}${this.session.username ? ` as ${this.session.username}` : ""}`);
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
    this.recorder?.dispose();
    this.recorder = null;
    this.definitions?.el.remove();
    this.definitions = null;
  }

  render(client) {
    this.clear();
    const outline = new RobdefOutline(client.$definitions);
    this.definitions = new DefinitionView(this.defBox, outline, `def-${this.name}`);
    this.typeEl.textContent = client.$type;
    const recorder = this.recorder = new RecordControl(this.tools, { device: this.name, members: client.$members });
    if (this.replayFile) recorder.markReplay(this.replayFile);
    this.mayRecordDevice().then((may) => { if (!may) recorder.refuse("Your login may not record this device (it needs the record right on the device)."); });
    // the device's types described once, from the definitions it sent (views/context.js)
    const view = viewContext(outline, { registry: this.renderers });
    this.panel = new ObjectPanel(this.members, {
      // every wire, pipe, event and callback of the page through the session's one subscription
      obj: client, live: new LiveObject(this.session.subscription), outline, view, panels: this.panels, definitions: this.definitions, log: this.log, memory: this.memory, path: "",
      // for panels that ask the gateway about this device (the robot panel: access, locks)
      device: this.name, session: this.session, devices: this.list,
    });
  }

  close() {
    this.closed = true;
    this.replay?.dispose();
    this.list.removeEventListener("update", this.onDevices);
    this.session.stop();
    this.clear();
    this.el.remove();
  }
}

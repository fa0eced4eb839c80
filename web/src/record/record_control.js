// The Record control of a device (issue 44, docs/dashboard.md "Recording and replay"): which members
// to record (checkboxes), the encoding, an optional directory on the gateway, Record/Stop, and the
// device's recordings with their state, duration, size, messages, drops, files and error, polled from
// GET api/recordings every second. The gateway records; this only asks it (recording_api.js).

import { h, errorText } from "../dom.js";
import {
  DEFAULT_KINDS, recordableMembers, parseMemberPaths, recordingBody, recordingsOf, formatBytes, formatSeconds,
  listRecordings, startRecording, stopRecording,
} from "./recording_api.js";

const POLL_MS = 1000;
const ACTIVE = new Set(["recording", "stopping"]);

/** One recording as a list item: "#3 recording 0:04.2 · 12.0 KiB · 120 messages · 0 drops", its files and error. */
function recordingItem(r) {
  const facts = [`${formatSeconds(r.duration_s)}`, formatBytes(r.bytes), `${r.messages} messages`, `${r.drops} drops`];
  return h("li", { class: "recording", dataset: { id: String(r.id), state: r.state } },
    h("span", { class: "recording-id", text: `#${r.id}` }),
    h("span", { class: "badge", dataset: { state: r.state === "recording" ? "connected" : r.state === "failed" ? "failed" : "idle" }, text: r.state }),
    h("span", { class: "recording-facts", text: facts.join(" · ") }),
    r.error ? h("p", { class: "recording-error", role: "alert", text: r.error }) : null,
    h("ul", { class: "recording-files" }, ...(r.files || []).map((f) => h("li", {}, h("code", { text: f })))));
}

export class RecordControl {
  /**
   * @param {HTMLElement} parent  where the section goes
   * @param {{device: string, members: {name: string, kind: string}[], fetchImpl?: Function}} opts
   *   members: the device's root members ($members of its proxy)
   */
  constructor(parent, { device, members, fetchImpl = globalThis.fetch }) {
    this.device = device;
    this.fetchImpl = fetchImpl;
    this.members = recordableMembers(members);
    this.boxes = this.members.map((m) => h("input", { type: "checkbox", name: "record-member", value: m.name, checked: DEFAULT_KINDS.includes(m.kind) }));
    this.encoding = h("select", { name: "record-encoding" },
      h("option", { value: "both", text: "json + robotraconteur" }),
      h("option", { value: "json", text: "json (Foxglove)" }),
      h("option", { value: "robotraconteur", text: "robotraconteur (replay)" }));
    this.directory = h("input", { name: "record-directory", placeholder: "a sub-folder of the recordings root (optional)", size: 28 });
    // members of objects below the root, by path: offered when the device has objrefs
    const objref = (members || []).find((m) => m.kind === "objref");
    this.paths = objref ? h("input", { name: "record-paths", size: 28, placeholder: `e.g. ${objref.name}[0].member, …` }) : null;
    this.button = h("button", { type: "button", class: "record-button", text: "Record", onclick: () => this.toggle() });
    this.live = h("span", { class: "record-live", "aria-live": "polite" });
    this.error = h("p", { class: "record-error", role: "alert", hidden: true });
    this.list = h("ul", { class: "recordings" });
    const memberList = h("div", { class: "record-members" }, ...this.members.map((m, i) =>
      h("label", {}, this.boxes[i], h("span", { text: m.name }), h("span", { class: "member-kind", text: m.kind }))));
    const all = (on) => () => { for (const b of this.boxes) b.checked = on; };
    this.heading = h("h3", { text: "Recording" });
    this.el = h("section", { class: "record-control", dataset: { state: "idle" } },
      this.heading,
      h("details", { class: "record-options" },
        h("summary", { text: "Members and options" }),
        h("div", { class: "record-select" },
          h("button", { type: "button", class: "small", text: "all", onclick: all(true) }),
          h("button", { type: "button", class: "small", text: "none", onclick: all(false) })),
        memberList,
        this.paths ? h("label", { title: "object path, '.', member; separated by commas or spaces" },
          h("span", { text: "Below the root" }), this.paths) : null,
        h("label", {}, h("span", { text: "Encoding" }), this.encoding),
        h("label", {}, h("span", { text: "Directory" }), this.directory)),
      h("div", { class: "record-row" }, this.button, this.live),
      this.error,
      this.list);
    parent.append(this.el);
    this.active = null;
    this.poll();
    this.timer = setInterval(() => this.poll(), POLL_MS);
  }

  /**
   * Says that the device is a replay of `file` (docs/recording.md "Recording a replay"): recording it
   * stays possible (to cut a part, or to get the json encoding of a file that has only robotraconteur
   * channels), and the section says what such a recording holds. Called once; later calls do nothing.
   * @param {string} file  the replayed file's path on the gateway (the replay status's `file`)
   */
  markReplay(file) {
    if (this.el.dataset.replay) return;
    this.el.dataset.replay = "true";
    this.heading.textContent = "Record this replay";
    this.heading.after(h("p", { class: "hint record-replay-note",
      text: `This device is a replay of ${file}. A recording takes what the replay plays from now on ` +
        "(time stamps of now, not of the original): to cut a part, seek, Record, play, Stop." }));
  }

  /** Disables starting a recording, saying why (the gateway would refuse it: 403). */
  refuse(reason) {
    this.refused = true;
    if (!this.active) this.button.disabled = true;
    this.button.title = reason;
    this.el.querySelector(".record-row").after(h("p", { class: "hint record-refused", text: reason }));
  }

  showError(text) {
    this.error.textContent = text || "";
    this.error.hidden = !text;
  }

  async poll() {
    try {
      this.show(recordingsOf(await listRecordings(this.fetchImpl), this.device));
    } catch (e) {
      // a gateway that went away: the device list says so; keep the last list
      if (e.status) this.showError(`recordings: ${errorText(e)}`);
    }
  }

  /** Shows the device's recordings (newest first); the newest active one is what Stop stops. */
  show(recs) {
    if (this.disposed) return;
    this.active = recs.find((r) => ACTIVE.has(r.state)) ?? null;
    const newest = recs[0];
    this.el.dataset.state = this.active ? this.active.state : newest?.state === "failed" ? "failed" : "idle";
    this.button.textContent = this.active ? "Stop" : "Record";
    this.button.dataset.action = this.active ? "stop" : "record";
    // a login without the right may still see a recording someone else started, not start one
    if (!this.busy) this.button.disabled = this.active ? this.active.state === "stopping" : Boolean(this.refused);
    this.live.textContent = this.active
      ? `● ${this.active.state} ${formatSeconds(this.active.duration_s)} · ${formatBytes(this.active.bytes)} · ${this.active.messages} messages · ${this.active.drops} drops`
      : "";
    this.list.replaceChildren(...recs.map(recordingItem));
  }

  async toggle() {
    this.busy = true;
    this.button.disabled = true;
    this.showError("");
    try {
      if (this.active) {
        await stopRecording(this.active.id, this.fetchImpl);
      } else {
        const members = [...this.members.filter((_, i) => this.boxes[i].checked).map((m) => m.name),
          ...parseMemberPaths(this.paths?.value)];
        await startRecording(recordingBody({ device: this.device, members, encoding: this.encoding.value, directory: this.directory.value }), this.fetchImpl);
      }
    } catch (e) {
      // e.g. 507 with the recorder's reason for an unwritable directory or a full disk
      this.showError(errorText(e));
    } finally {
      this.busy = false;
      this.button.disabled = false;
      await this.poll();
    }
  }

  dispose() {
    this.disposed = true;
    clearInterval(this.timer);
    this.el.remove();
  }
}

// Small parts the sensor, laser scanner and point cloud panels share: the error line of a panel and
// the gateway's access answer that decides their controls.

import { h, errorText } from "../dom.js";
import { fetchAccess } from "../robot/access.js";

/**
 * The error line of a panel: { el, show(text|null), onMemberError(member) } where onMemberError gives
 * the onError handler of a followed wire or pipe (its error shown, cleared once it is open again).
 * `alive()` false after the panel is gone: nothing is shown then.
 */
export function errorLine(className, alive) {
  const el = h("div", { class: `member-error ${className}`, role: "alert", hidden: true });
  const show = (text) => { if (alive()) { el.textContent = text || ""; el.hidden = !text; } };
  const onMemberError = (member) => (e) => {
    if (e) show(`${member}: ${errorText(e)}`);
    else if (el.textContent.startsWith(`${member}:`)) show(null);
  };
  return { el, show, onMemberError };
}

/**
 * Once the gateway said what this page's user may do on the device (robot/access.js) and `ready` has
 * settled: `panelEl.dataset.access` ("all", "checked", or "none" when the answer failed: no control)
 * and then(access). Without a device name (a page of its own) everything is allowed.
 */
export function whenAccess(ctx, panelEl, ready, alive, then, showError) {
  const accessRead = ctx.device ? fetchAccess(ctx.device, ctx.session?.username ?? null) : Promise.resolve({ members: null });
  Promise.all([accessRead, ready]).then(([access]) => {
    if (!alive()) return;
    panelEl.dataset.access = access.members === null ? "all" : "checked";
    then(access);
  }, (e) => {
    if (!alive()) return;
    panelEl.dataset.access = "none";
    showError(`${e.message}: no controls`);
  });
}

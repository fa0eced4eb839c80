// The frame every member is shown in: name, kind, robdef type (linked to its definition), a body,
// and an error line that shows device errors in place.

import { h, errorText } from "../dom.js";
import { isNumericBase } from "../std/rr_types.js";

/** The member's signature as robdef writes it (for functions and callbacks, with parameters). */
export function signature(member) {
  const params = (member.params || []).map((p) => `${p.type} ${p.name}`).join(", ");
  if (member.kind === "function" || member.kind === "callback") return `${member.type} ${member.name}(${params})`;
  if (member.kind === "event") return `${member.name}(${params})`;
  return `${member.type} ${member.name}`;
}

function modifiers(member) {
  const mods = [];
  if (member.readonly) mods.push("readonly");
  if (member.writeonly) mods.push("writeonly");
  if (member.generator) mods.push("generator");
  return mods;
}

/**
 * A member card. ctx.linkType(name) makes a link to a named type's definition (or null). `described`
 * (the member's descriptor, views/context.js): when the device's definition of a standard type has
 * another layout than the one its renderer reads, the card says so and the values are shown plainly.
 * Returns { el, body, tools, showError(err), clearError() }.
 */
export function memberCard(ctx, member, described = null) {
  const typeEl = h("code", { class: "member-type" });
  const words = signature(member).split(/([\s,()<>{}\[\]]+)/);
  for (const w of words) {
    // the separators cut the signature into names: each word is a type name, a member name or a keyword
    const link = /^[A-Za-z_][\w.]*$/.test(w) ? ctx.linkType?.(w) : null;
    typeEl.append(link || w);
  }
  const error = h("div", { class: "member-error", role: "alert", hidden: true });
  const tools = h("div", { class: "member-tools" });
  const body = h("div", { class: "member-body" });
  const mismatch = described?.type?.mismatch ?? described?.type?.element?.mismatch;
  if (mismatch) body.append(h("div", { class: "hint type-fallback", text: `shown as plain values: ${mismatch}` }));
  const el = h("section", { class: `member member-${member.kind}`, dataset: { member: member.name, kind: member.kind } },
    h("header", { class: "member-title" },
      h("span", { class: "member-name", text: member.name }),
      h("span", { class: `kind kind-${member.kind}`, text: member.kind }),
      ...modifiers(member).map((m) => h("span", { class: "modifier", text: m })),
      tools),
    typeEl, body, error);
  return {
    el, body, tools,
    showError(err) {
      error.textContent = errorText(err); error.hidden = false; el.classList.add("has-error");
      error.dataset.shown = String(Number(error.dataset.shown || 0) + 1);  // tells a new error from a stale one
    },
    clearError() { error.hidden = true; error.textContent = ""; el.classList.remove("has-error"); },
  };
}

/** An input for a value of type descriptor `d` (std/describe.js): a checkbox for bool, a list of names
 * for enums, a text field for numbers and numeric vectors, a text area for strings (they may hold line
 * breaks), a JSON text area for everything else. `.read()` gives the text ("true"/"false" for the checkbox). */
export function valueInput(d, label) {
  const t = d;
  if (t.base === "bool" && !t.array && !t.container) {
    const box = h("input", { type: "checkbox", "aria-label": label });
    return { el: box, read: () => String(box.checked), write: (text) => { box.checked = text === "true"; } };
  }
  const values = !t.container && !t.array && t.kind === "enum" ? t.enumValues : null;
  if (values) {
    const select = h("select", { "aria-label": label },
      ...values.map((v) => h("option", { value: v.name, text: `${v.name} (${v.value})` })));
    const write = (text) => {
      const found = values.find((v) => v.name === text || String(v.value) === String(text).trim());
      if (found) select.value = found.name;
    };
    return { el: select, read: () => select.value, write };
  }
  const simple = !t.container && (!t.array || (t.array === "vector" && t.base !== "string"))
    && isNumericBase(t.base);
  let el;
  if (simple) el = h("input", { type: "text", "aria-label": label, placeholder: t.array ? "1, 2, 3" : t.base, spellcheck: "false" });
  else if (t.base === "string" && !t.array && !t.container) el = h("textarea", { rows: 1, "aria-label": label, placeholder: "string", spellcheck: "false" });
  else el = h("textarea", { rows: 2, "aria-label": label, placeholder: "JSON", spellcheck: "false" });
  return { el, read: () => el.value, write: (text) => { el.value = text; } };
}

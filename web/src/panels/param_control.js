// A device's parameters through its getf_param / setf_param functions (sensors, laser scanners, point
// cloud sensors): the names its ParameterInfo list offers (or one typed in), Get shows the value, Set
// sends a number. Shown only to users the gateway lets call the function (robot/access.js); the
// gateway still checks each call, and a refusal or the driver's error is shown in place.

import { h, errorText } from "../dom.js";
import { allows } from "../robot/access.js";
import { parseInput } from "../value_codec.js";
import { describeMember } from "../views/context.js";

/** The parameter names of a ParameterInfo{list} value (parameter_identifier.name), [] when absent. */
export function parameterNames(paramInfo) {
  if (!paramInfo || typeof paramInfo.length !== "number") return [];
  return Array.from(paramInfo, (p) => p?.parameter_identifier?.name).filter((n) => typeof n === "string" && n);
}

/** The text of a varvalue returned by getf_param. */
function varText(v) {
  const inner = v && typeof v === "object" && "type" in v && "value" in v ? v.value : v;
  if (ArrayBuffer.isView(inner)) return inner.length === 1 ? String(inner[0]) : `[${Array.from(inner).join(", ")}]`;
  if (typeof inner === "bigint") return String(inner);
  if (typeof inner === "string") return inner;
  return JSON.stringify(inner);
}

/**
 * Adds the parameter control to `box` when the object has getf_param or setf_param and `access` allows
 * calling them. `names`: parameter names to offer. Returns the control's element or null.
 */
export function buildParamControl(box, { obj, view, access, names = [], onError }) {
  const find = (name) => (obj.$members || []).find((m) => m.name === name && m.kind === "function") || null;
  const getter = find("getf_param"), setter = find("setf_param");
  const mayGet = getter && allows(access, "getf_param", "call");
  const maySet = setter && allows(access, "setf_param", "call");
  if (!mayGet && !maySet) return null;
  const listId = `params-${Math.random().toString(36).slice(2)}`;
  const name = h("input", { type: "text", class: "param-name", "aria-label": "parameter", list: listId, value: names[0] ?? "", size: 14 });
  const list = h("datalist", { id: listId }, ...names.map((n) => h("option", { value: n })));
  const value = h("input", { type: "text", class: "param-value", "aria-label": "parameter value", size: 10 });
  const out = h("output", { class: "param-result" });
  const run = async (button, what) => {
    button.disabled = true;
    try {
      out.textContent = await what();
      onError?.(null);
    } catch (e) {
      out.textContent = "";
      onError?.(`${button.dataset.action}: ${errorText(e)}`);
    } finally {
      button.disabled = false;
    }
  };
  const el = h("div", { class: "param-control", dataset: { panelPart: "params" } }, h("span", { class: "hint", text: "parameter" }), name, list);
  if (mayGet) {
    const b = h("button", { type: "button", class: "small", text: "Get", dataset: { action: "getf_param" } });
    b.addEventListener("click", () => run(b, async () => varText(await obj.getf_param(name.value))));
    el.append(b);
  }
  if (maySet) {
    const d = describeMember(view, obj, setter);
    const b = h("button", { type: "button", class: "small", text: "Set", dataset: { action: "setf_param" } });
    b.addEventListener("click", () => run(b, async () => {
      const n = Number(value.value);
      if (value.value.trim() === "" || !Number.isFinite(n)) throw new Error("a number expected");
      const arg = d?.params?.[1] ? parseInput(d.params[1].type ?? d.params[1], JSON.stringify({ type: "double", value: n })) : { type: "double", value: n };
      await obj.setf_param(name.value, arg);
      return `set ${name.value} = ${n}`;
    }));
    el.append(value, b);
  }
  el.append(out);
  box.append(el);
  return el;
}

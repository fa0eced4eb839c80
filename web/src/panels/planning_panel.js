// The planning panel, for the alpha planning types com.robotraconteur.a1.robotics.planning Planner and
// PlanningScene: a readable view, nothing more (no planning is started from the page). For a Planner,
// planner_info's algorithms and filters (name: description) and its `scene` objref opened; for the
// scene, planning_scene_info, the root link, the robots' names, the joint positions, and the Scene as a
// tree of links from the root down, each joint named with its type between parent and child link,
// models' links marked with their model (planning/scene_tree.js). Each part only when the device has
// the member; a Planner without planner_info or scene gets one line and the generic view below.

import { h, errorText } from "../dom.js";
import { objectTypes } from "./registry.js";
import { enumName } from "../std/enums.js";
import { errorLine } from "./panel_parts.js";
import { sceneTree, treeLines } from "../planning/scene_tree.js";

const P = "com.robotraconteur.a1.robotics.planning";
export const PLANNING_TYPES = [`${P}.Planner`, `${P}.PlanningScene`];

const has = (obj, name, kind) => (obj?.$members || []).some((m) => m.name === name && m.kind === kind);
const nameOf = (id) => id?.name ?? "";
const keysOf = (map) => (map instanceof Map ? [...map.keys()] : Object.keys(map ?? {}));

export function createPlanningPanel(parent, ctx) {
  const { obj, view } = ctx;
  const jointTypes = view?.outline?.types?.get("com.robotraconteur.robotics.joints.JointType")?.values ?? [];
  let disposed = false;
  const errors = errorLine("planning-error", () => !disposed);
  const rows = h("dl", { class: "camera-info-rows planning-rows" });
  const tree = h("pre", { class: "planning-tree", style: "margin: 4px 0; max-height: 360px; overflow: auto" });
  const el = h("section", { class: "panel planning-panel", dataset: { panel: "planning" } }, h("h3", { text: "Planning scene" }), errors.el, rows, tree);
  parent.append(el);
  const row = (key, label, text) => rows.append(h("dt", { text: label }), h("dd", { dataset: { row: key }, text }));
  const read = async (o, name, fn) => {
    if (!has(o, name, "property")) return;
    try { fn(await o[name].get()); } catch (e) { errors.show(`${name}: ${errorText(e)}`); }
  };

  async function showScene(scene) {
    await read(scene, "planning_scene_info", (i) => row("scene", "scene", [nameOf(i?.scene_identifier), i?.description].filter(Boolean).join(": ")));
    let root = "";
    await read(scene, "root_link_name", (r) => { root = nameOf(r); row("root_link_name", "root link", root); });
    await read(scene, "robots", (r) => row("robots", "robots", keysOf(r).join(", ") || "none"));
    await read(scene, "joint_position", (p) => {
      const j = p?.joint_position ?? {};
      const text = keysOf(j).map((k) => `${k} ${Array.from((j instanceof Map ? j.get(k) : j[k]) ?? [], (v) => Number(v).toFixed(4)).join(", ")}`).join("; ");
      row("joint_position", "joint positions", text || "none");
    });
    await read(scene, "scene", (s) => {
      const t = sceneTree(s, root);
      row("links", "links", `${t.placed} of ${t.total} placed${Array.from(s?.models ?? []).length ? `, models ${Array.from(s.models).map((m) => nameOf(m.model_identifier)).join(", ")}` : ""}`);
      tree.textContent = treeLines(t.tree, (v) => enumName(jointTypes, v) ?? String(v)).join("\n");
    });
  }

  const types = objectTypes(obj);
  let done;
  if (types.has(`${P}.Planner`) && (has(obj, "planner_info", "property") || has(obj, "scene", "objref"))) {
    done = (async () => {
      await read(obj, "planner_info", (i) => {
        const algos = (list) => Array.from(list ?? []).map((a) => `${nameOf(a.algorithm_identifier)}${a.description ? `: ${a.description}` : ""}`).join("; ");
        row("algorithms", "algorithms", algos(i?.planner_algorithms) || "none");
        if (Array.from(i?.planner_filters ?? []).length) row("filters", "filters", algos(i.planner_filters));
      });
      if (has(obj, "scene", "objref")) await showScene(await obj.scene.get());
    })();
  } else if (types.has(`${P}.PlanningScene`) && has(obj, "scene", "property")) {
    done = showScene(obj);
  } else {
    el.dataset.fallback = "true";
    tree.hidden = true;
    rows.append(h("span", { class: "hint", text: "this planner has none of planner_info, scene of the alpha planning definitions: its members are shown below" }));
    return { el, dispose() { el.remove(); } };
  }
  done.catch((e) => errors.show(`scene: ${errorText(e)}`)).finally(() => { if (!disposed) el.dataset.ready = "true"; });
  return { el, dispose() { disposed = true; el.remove(); } };
}

export const planningPanel = { name: "planning", order: 20, types: PLANNING_TYPES, create: createPlanningPanel };

// The planning panel's pure logic (panels/planning_panel.js): a com.robotraconteur.a1.robotics.scene
// Scene (links, joints joining a parent link to a child link, models of their own links and joints) as
// a tree a person reads from the root link down. Bounded: at most MAX_LINKS links are placed; a link
// reached twice (a loop in a bad scene) is placed once.

export const MAX_LINKS = 2000;

const nameOf = (id) => (typeof id === "string" ? id : id?.name ?? "");

/** The joints and links of a scene and of all its models, each link and joint with its model's name. */
export function sceneParts(scene) {
  const links = [], joints = [];
  const take = (owner, model) => {
    for (const l of Array.from(owner?.links ?? [])) links.push({ name: nameOf(l?.link_identifier), type: l?.link_type ?? "", model });
    for (const j of Array.from(owner?.joints ?? [])) {
      joints.push({ name: nameOf(j?.joint_info?.joint_identifier), parent: j?.parent_link_name ?? "", child: j?.child_link_name ?? "", model, type: j?.joint_info?.joint_type });
    }
  };
  take(scene, "");
  for (const m of Array.from(scene?.models ?? [])) take(m, nameOf(m?.model_identifier));
  return { links, joints };
}

/**
 * The tree [{ link, model, via (the joint leading here: { name, type } or null), children }] from the
 * links no joint leads to (the roots; `rootName` first when given), and the count of links placed.
 */
export function sceneTree(scene, rootName = "") {
  const { links, joints } = sceneParts(scene);
  const byParent = new Map();
  for (const j of joints) { if (!byParent.has(j.parent)) byParent.set(j.parent, []); byParent.get(j.parent).push(j); }
  const children = new Set(joints.map((j) => j.child));
  const linkModel = new Map(links.map((l) => [l.name, l.model]));
  const names = [...new Set([...links.map((l) => l.name), ...joints.flatMap((j) => [j.parent, j.child])])].filter(Boolean);
  let roots = names.filter((n) => !children.has(n));
  if (rootName && names.includes(rootName)) roots = [rootName, ...roots.filter((n) => n !== rootName)];
  const placed = new Set();
  const build = (name, via) => {
    if (placed.has(name) || placed.size >= MAX_LINKS) return null;
    placed.add(name);
    const kids = (byParent.get(name) ?? []).map((j) => build(j.child, { name: j.name, type: j.type })).filter(Boolean);
    return { link: name, model: linkModel.get(name) ?? "", via, children: kids };
  };
  const tree = roots.map((r) => build(r, null)).filter(Boolean);
  return { tree, placed: placed.size, total: names.length };
}

/** Text lines of a tree, indented two spaces a level: "base_link", "  joint_1 (revolute) → link_1". */
export function treeLines(tree, jointTypeName = (t) => (t === undefined ? "" : String(t))) {
  const out = [];
  const walk = (node, depth) => {
    const via = node.via ? `${node.via.name}${node.via.type !== undefined ? ` (${jointTypeName(node.via.type)})` : ""} → ` : "";
    out.push(`${"  ".repeat(depth)}${via}${node.link}${node.model ? ` [${node.model}]` : ""}`);
    for (const c of node.children) walk(c, depth + 1);
  };
  for (const n of tree) walk(n, 0);
  return out;
}

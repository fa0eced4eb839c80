#!/usr/bin/env python3
"""A motion planner served by the official library with the alpha planning definitions
(com.robotraconteur.a1.robotics.planning and .scene, read from $RR_SHARED_DIR/robdef-standard/group2:
RobotRaconteurCompanion does not ship them). The draft's scene file names its service
com.robotraconteur.robotics.scene while the planning file imports com.robotraconteur.a1.robotics.scene;
the service line is renamed to what the planning file imports, nothing else is changed.

"planner" is a Planner with two algorithms (ompl_rrt, a straight-line joint interpolator) whose `scene`
is a PlanningScene "cell": root link "world"; the links world, table, robot_base, link_1, link_2,
tool0; the joints table_mount (fixed to world), base_mount, joint_1 (revolute), joint_2 (revolute),
flange; a model "robot" holding robot_base … tool0 with their joints; joint positions of the robot
[0.1, -0.2]; the robot "arm". Nothing is planned: plan() refuses.

Ready line: {"url": ".../?service=planner", "port": P}. Exits 77 with "SKIP: ..." when the definitions
are missing.

Usage: planning.py [--max-lifetime 300]
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import die_with_parent, free_port, node_flags, ready, wait_for_stop, log  # noqa: E402

import numpy as np  # noqa: E402
import RobotRaconteur as RR  # noqa: E402
import RobotRaconteurCompanion as RRC  # noqa: E402

RRN = RR.RobotRaconteurNode.s
P = "com.robotraconteur.a1.robotics.planning"
S = "com.robotraconteur.a1.robotics.scene"


def definitions():
    shared = os.environ.get("RR_SHARED_DIR") or os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../../../shared")
    d = os.path.join(shared, "robdef-standard", "group2")
    try:
        scene = open(os.path.join(d, f"{S}.robdef")).read()
        plan = open(os.path.join(d, f"{P}.robdef")).read()
    except OSError as e:
        print(f"SKIP: alpha planning definitions missing: {e} (set RR_SHARED_DIR)", flush=True)
        sys.exit(77)
    return [scene.replace("service com.robotraconteur.robotics.scene", f"service {S}", 1), plan]


def identifier(name):
    i = RRN.NewStructure("com.robotraconteur.identifier.Identifier")
    i.name = name
    i.uuid = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.uuid.UUID"))
    return i


def joint(name, jtype, parent, child):
    j = RRN.NewStructure(f"{S}.Joint")
    info = RRN.NewStructure("com.robotraconteur.robotics.joints.JointInfo")
    info.joint_identifier = identifier(name)
    info.joint_type = RRN.GetConstants("com.robotraconteur.robotics.joints")["JointType"][jtype]
    info.passive, info.extended = False, {}
    j.joint_info, j.parent_link_name, j.child_link_name, j.extended = info, parent, child, {}
    j.axis = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.geometry.Vector3"))
    j.parent_to_joint_origin_transform = np.zeros((1,), dtype=RRN.GetNamedArrayDType("com.robotraconteur.geometry.Pose"))
    return j


def link(name):
    lk = RRN.NewStructure(f"{S}.Link")
    lk.link_identifier, lk.link_type, lk.visual, lk.collision, lk.extended = identifier(name), "", [], [], {}
    return lk


class Scene:
    def __init__(self):
        info = RRN.NewStructure(f"{P}.PlanningSceneInfo")
        info.scene_identifier, info.description, info.scene_capabilities = identifier("cell"), "work cell 3", 0
        info.scene_parameter_info, info.extended = [], {}
        self.planning_scene_info = info
        self.root_link_name = identifier("world")
        model = RRN.NewStructure(f"{S}.Model")
        model.model_identifier, model.parent_identifier = identifier("robot"), identifier("world")
        model.links = [link(n) for n in ("robot_base", "link_1", "link_2", "tool0")]
        # the other "unknown" joint types are simply not moving here: the standard has no "fixed"
        model.joints = [joint("joint_1", "revolute", "robot_base", "link_1"), joint("joint_2", "revolute", "link_1", "link_2"),
                        joint("flange", "other", "link_2", "tool0")]
        model.extended = {}
        scene = RRN.NewStructure(f"{S}.Scene")
        scene.scene_identifier = identifier("cell")
        scene.links = [link("world"), link("table")]
        scene.joints = [joint("table_mount", "other", "world", "table"), joint("base_mount", "other", "table", "robot_base")]
        scene.models, scene.revision, scene.extended = [model], 3, {}
        self.scene = scene
        jp = RRN.NewStructure(f"{P}.PlannerJointPositions")
        mj = RRN.NewStructure(f"{P}.PlannerModelJointPositions")
        mj.joint_position = {"joint_1": np.array([0.1]), "joint_2": np.array([-0.2])}
        jp.model_joints, jp.joint_position, jp.extended = {"robot": mj}, {"joint_1": np.array([0.1]), "joint_2": np.array([-0.2])}, {}
        self.joint_position = jp
        self.robots = {}
        self.link_names = [identifier(n) for n in ("world", "table", "robot_base", "link_1", "link_2", "tool0")]
        self.joint_names = [identifier(n) for n in ("table_mount", "base_mount", "joint_1", "joint_2", "flange")]
        self.active_joint_names = [identifier("joint_1"), identifier("joint_2")]


class Planner:
    def __init__(self):
        info = RRN.NewStructure(f"{P}.PlannerInfo")
        info.device_info = None
        algos = []
        for name, description in (("ompl_rrt", "sampling-based, collision-free"), ("joint_line", "straight line in joint space")):
            a = RRN.NewStructure(f"{P}.PlannerAlgorithmInfo")
            a.algorithm_identifier, a.description = identifier(name), description
            a.algorithm_classes, a.algorithm_capability_flags, a.algorithm_capabilities = [], 0, []
            a.waypoint_constraints, a.waypoint_extended, a.algorithm_specific, a.extended = [], [], [], {}
            algos.append(a)
        info.planner_algorithms, info.planner_filters, info.global_parameter_info, info.extended = algos, [], [], {}
        self.planner_info = info
        self._scene = Scene()

    def get_scene(self):
        return self._scene, f"{P}.PlanningScene"

    def plan(self, request):
        raise RR.NotImplementedException("this test planner plans nothing")


def main():
    die_with_parent()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-lifetime", type=float, default=300)
    args = ap.parse_args()
    defs = definitions()
    port = free_port()
    with RR.ServerNodeSetup("experimental.sim_planner", port, argv=["planning"] + node_flags(port)):
        RRC.RegisterStdRobDefServiceTypes(RRN)
        RRN.RegisterServiceTypes(defs)
        planner = Planner()
        RRN.RegisterService("planner", f"{P}.Planner", planner)
        ready(url=f"rr+tcp://127.0.0.1:{port}/?service=planner", port=port, pid=os.getpid())
        wait_for_stop(args.max_lifetime)
        log("planning", "stopping")


if __name__ == "__main__":
    main()

"""The simulated body tree shared by every character: 16 bodies named by the canonical body
parts, 15 ball joints, their parents and joint cones."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

__all__ = [
    "BALL_JOINTS",
    "BALL_JOINT_INDEX",
    "BODY_ALIASES",
    "JOINT_RANGE",
    "SIM_BODIES",
    "SIM_BODY_INDEX",
    "SIM_PARENTS",
    "TREE",
]

# (body = part, parent body, ball joint name); preorder, which is MuJoCo's body/joint order.
TREE: tuple[tuple[str, str | None, str | None], ...] = (
    ("pelvis", None, None),
    ("waist", "pelvis", "waist"),
    ("chest", "waist", "back"),
    ("head", "chest", "neck"),
    ("l_upper_arm", "chest", "l_shoulder"),
    ("l_forearm", "l_upper_arm", "l_elbow"),
    ("l_hand", "l_forearm", "l_wrist"),
    ("r_upper_arm", "chest", "r_shoulder"),
    ("r_forearm", "r_upper_arm", "r_elbow"),
    ("r_hand", "r_forearm", "r_wrist"),
    ("l_thigh", "pelvis", "l_hip"),
    ("l_shin", "l_thigh", "l_knee"),
    ("l_foot", "l_shin", "l_ankle"),
    ("r_thigh", "pelvis", "r_hip"),
    ("r_shin", "r_thigh", "r_knee"),
    ("r_foot", "r_shin", "r_ankle"),
)
SIM_BODIES: tuple[str, ...] = tuple(b for b, _, _ in TREE)
BALL_JOINTS: tuple[str, ...] = tuple(j for _, _, j in TREE if j is not None)
BODY_ALIASES: Mapping[str, str] = {"abdomen": "waist", "thorax": "chest", "neck": "head"}
#: index in BALL_JOINTS of each joint name
BALL_JOINT_INDEX: Mapping[str, int] = {j: i for i, j in enumerate(BALL_JOINTS)}
#: index in SIM_BODIES of each body name
SIM_BODY_INDEX: Mapping[str, int] = {b: i for i, b in enumerate(SIM_BODIES)}
#: parent body index of each of SIM_BODIES (-1 for the pelvis)
SIM_PARENTS = np.array([-1 if p is None else SIM_BODIES.index(p) for _, p, _ in TREE])

#: cone half-angle (rad) of each ball joint around its reference-pose rotation. MuJoCo ball
#: limits are cones, so these are coarse: they stop wild twists after hard impacts, they do not
#: model anatomy (a knee cone also allows hyperextension).
JOINT_RANGE: Mapping[str, float] = {
    "waist": 1.0, "back": 1.0, "neck": 1.3, "shoulder": 2.9, "elbow": 2.7, "wrist": 1.7,
    "hip": 2.4, "knee": 2.7, "ankle": 1.3,
}  # fmt: skip

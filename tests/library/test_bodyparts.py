"""Body-part mapping across naming styles, TOML overrides and located failures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reactmocap.errors import BodyPartMappingError, ConfigError
from reactmocap.library.bodyparts import BODY_PARTS, OPTIONAL_PARTS, load_rules, map_body_parts
from reactmocap.library.skeleton import Skeleton


def skeleton(names: list[str], parents: list[int]) -> Skeleton:
    return Skeleton(tuple(names), parents, np.zeros((len(names), 3)))


BANDAI = (
    ["joint_Root", "Hips", "Spine", "Chest", "Neck", "Head", "Shoulder_L", "UpperArm_L",
     "LowerArm_L", "Hand_L", "Shoulder_R", "UpperArm_R", "LowerArm_R", "Hand_R", "UpperLeg_L",
     "LowerLeg_L", "Foot_L", "Toes_L", "UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R"],
    [-1, 0, 1, 2, 3, 4, 3, 6, 7, 8, 3, 10, 11, 12, 1, 14, 15, 16, 1, 18, 19, 20],
)  # fmt: skip
MIXAMO_BASE = ["Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm",
               "LeftForeArm", "LeftHand", "RightShoulder", "RightArm", "RightForeArm",
               "RightHand", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg",
               "RightLeg", "RightFoot", "RightToeBase"]  # fmt: skip
MIXAMO_PARENTS = [-1, 0, 1, 2, 3, 4, 3, 6, 7, 8, 3, 10, 11, 12, 0, 14, 15, 16, 0, 18, 19, 20]
CMU_ASF = (
    ["hip", "lowerback", "upperback", "thorax", "lowerneck", "head", "lclavicle", "lhumerus",
     "lradius", "lwrist", "rclavicle", "rhumerus", "rradius", "rwrist", "lhipjoint", "lfemur",
     "ltibia", "lfoot", "ltoes", "rhipjoint", "rfemur", "rtibia", "rfoot", "rtoes"],
    [-1, 0, 1, 2, 3, 4, 3, 6, 7, 8, 3, 10, 11, 12, 0, 14, 15, 16, 17, 0, 19, 20, 21, 22],
)  # fmt: skip

EXPECT_BANDAI = {"pelvis": "Hips", "waist": "Spine", "chest": "Chest", "neck": "Neck",
                 "l_upper_arm": "UpperArm_L", "r_forearm": "LowerArm_R", "l_thigh": "UpperLeg_L",
                 "r_shin": "LowerLeg_R", "l_foot": "Foot_L", "r_toe": "Toes_R"}  # fmt: skip
EXPECT_MIXAMO = {"pelvis": "Hips", "waist": "Spine", "chest": "Spine2", "l_upper_arm": "LeftArm",
                 "l_forearm": "LeftForeArm", "r_hand": "RightHand", "l_thigh": "LeftUpLeg",
                 "l_shin": "LeftLeg", "r_foot": "RightFoot", "l_toe": "LeftToeBase"}  # fmt: skip


@pytest.mark.parametrize(
    ("names", "parents", "expected"),
    [
        (BANDAI[0], BANDAI[1], EXPECT_BANDAI),
        (MIXAMO_BASE, MIXAMO_PARENTS, EXPECT_MIXAMO),
        (["mixamorig:" + n for n in MIXAMO_BASE], MIXAMO_PARENTS,
         {k: "mixamorig:" + v for k, v in EXPECT_MIXAMO.items()}),
        ([n.lower() for n in MIXAMO_BASE], MIXAMO_PARENTS,
         {k: v.lower() for k, v in EXPECT_MIXAMO.items()}),
        (CMU_ASF[0], CMU_ASF[1], {"pelvis": "hip", "waist": "lowerback", "chest": "thorax",
                                  "l_thigh": "lfemur", "r_shin": "rtibia", "l_upper_arm": "lhumerus",
                                  "r_hand": "rwrist"}),
    ],
)  # fmt: skip
def test_naming_styles(names: list[str], parents: list[int], expected: dict[str, str]) -> None:
    bp = map_body_parts(skeleton(names, parents))
    for part, joint in expected.items():
        assert bp.name_of(part) == joint, part
    assert set(BODY_PARTS) - set(OPTIONAL_PARTS) <= set(bp.parts)
    # every mapped joint is distinct
    assert len(set(bp.joints.values())) == len(bp.joints)


def test_missing_parts_are_named_with_available_joints() -> None:
    names = ["Hips", "Spine", "Head", "LeftUpLeg", "LeftLeg", "LeftFoot"]
    with pytest.raises(BodyPartMappingError) as err:
        map_body_parts(skeleton(names, [-1, 0, 1, 0, 3, 4]))
    msg = str(err.value)
    assert "r_thigh" in msg and "l_upper_arm" in msg and "LeftUpLeg" in msg
    assert "'l_thigh'" not in msg.split("available")[0]


def test_toml_override(tmp_path: Path) -> None:
    names = ["root", "pelv", "abd", "tho", "skull"] + [
        f"{s}{p}" for s in ("L", "R") for p in ("_arm1", "_arm2", "_paw", "_leg1", "_leg2", "_ft")
    ]
    parents = [-1, 0, 1, 2, 3, 3, 5, 6, 1, 8, 9, 3, 11, 12, 1, 14, 15]
    rules = tmp_path / "rules.toml"
    lines = ["[parts]", 'pelvis = "pelv"', 'waist = "abd"', 'chest = "tho"', 'head = "skull"']
    for side in ("L", "R"):
        s = side.lower()
        for part, suffix in (("upper_arm", "_arm1"), ("forearm", "_arm2"), ("hand", "_paw"),
                             ("thigh", "_leg1"), ("shin", "_leg2"), ("foot", "_ft")):  # fmt: skip
            lines.append(f'{s}_{part} = "{side}{suffix}"')
    rules.write_text("\n".join(lines))
    bp = map_body_parts(skeleton(names, parents), rules)
    assert bp.name_of("r_shin") == "R_leg2"
    bad = tmp_path / "bad.toml"
    bad.write_text('[parts]\nelbow_thing = "x"\n')
    with pytest.raises(ConfigError, match="unknown part 'elbow_thing'"):
        map_body_parts(skeleton(names, parents), bad)
    missing = tmp_path / "missing.toml"
    missing.write_text('[parts]\npelvis = "nope"\n')
    with pytest.raises(BodyPartMappingError, match="'nope': no such joint"):
        map_body_parts(skeleton(names, parents), missing)


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ("[parts]\npelvis = 5\n", "[parts].pelvis: expected a joint name, got 5"),
        ("[parts]\nbogus = 'Hips'\n", "[parts] has unknown part 'bogus'"),
        ("[aliases]\nthigh = 'thighbone'\n", "[aliases].thigh: expected a list of names"),
        ("parts = 3\n", "[parts] must be a table, got 3"),
    ],
)
def test_a_bad_rules_file_is_refused_on_loading_naming_file_and_field(
    tmp_path: Path, text: str, field: str
) -> None:
    # before: `pelvis = 5` was accepted (the rules silently did not fit), and an unknown part
    # surfaced only as each clip's "not mappable" warning, without the file
    rules = tmp_path / "rules.toml"
    rules.write_text(text)
    with pytest.raises(ConfigError) as err:
        load_rules(rules)
    assert str(err.value).startswith(f"{rules}: {field}")


def test_aliases_extend_rules() -> None:
    names = list(MIXAMO_BASE)
    names[14] = "LeftThighBone"
    names[18] = "RightThighBone"
    with pytest.raises(BodyPartMappingError, match="l_thigh"):
        map_body_parts(skeleton(names, MIXAMO_PARENTS))
    bp = map_body_parts(skeleton(names, MIXAMO_PARENTS), {"aliases": {"thigh": ["thighbone"]}})
    assert bp.name_of("l_thigh") == "LeftThighBone"

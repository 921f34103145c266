"""Synthetic clip library: plausibility of every generated clip (ground, foot sliding, joint
ranges, durations, size), reproducibility, and that the committed files match the generator."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reactmocap.library.bodyparts import map_body_parts
from reactmocap.library.motion import Motion
from reactmocap.library.synth import (
    ATTACK_CLIPS,
    CLIP_INFO,
    STRIKERS,
    synthetic_clips,
    synthetic_skeleton,
    write_synthetic_library,
)
from reactmocap.rotations import quat_log
from tests.conftest import SYNTHETIC

FALLS = (
    "fall_backward", "fall_forward", "fall_sideways", "fall_backward_fast", "fall_forward_fast",
    "fall_sideways_fast", "fall_forward_topple", "fall_sideways_fast_right",
)  # fmt: skip

# Largest rotation from the rest pose (degrees) per joint; the root is free. A trained kicker's
# front-kick chamber flexes the hip to about 135-140 degrees with the knee bent.
MAX_ANGLE = {
    "Spine": 40, "Spine1": 40, "Neck": 50, "Head": 50, "Shoulder": 30, "Arm": 150,
    "ForeArm": 150, "Hand": 80, "UpLeg": 140, "Leg": 150, "Foot": 60, "ToeBase": 70,
}  # fmt: skip
# Hinges: (joint suffix, flexion axis in the joint's local frame). Knees flex about +Y (the foot
# goes back), elbows about -Y (the hand comes forward); flexion 0..150 deg, nothing off-axis.
HINGES = {"Leg": np.array([0.0, 1.0, 0.0]), "ForeArm": np.array([0.0, -1.0, 0.0])}
FOOT_POINTS = ("Foot", "ToeBase")  # plus the toe end sites
# A foot point this close to its standing height is on the ground; the ankle only with the heel
# down (a raised heel lifts it ~2.5 cm while the ball stays planted and it may swing about that).
CONTACT_ABOVE_REST = {"Foot": 0.02, "ToeBase": 0.03, "ToeTip": 0.03}
CONTACT_SPEED = 1.0  # m/s: faster than this is a swing skimming the floor, not a planted foot
MAX_SLIDE = 0.02


@pytest.fixture(scope="module")
def clips() -> dict[str, Motion]:
    return synthetic_clips()


def _points(m: Motion) -> np.ndarray:
    return np.concatenate([m.global_positions(), m.end_site_positions()], axis=1)


def _foot_tracks(m: Motion) -> dict[str, tuple[np.ndarray, float]]:
    """Name -> ((T, 3) world track, standing height) of each foot contact point."""
    ident = np.tile([1.0, 0.0, 0.0, 0.0], (1, m.num_joints, 1))
    rest = Motion(m.skeleton, m.fps, np.array([[0.0, 0.0, 0.95]]), ident)  # standing at rest
    pos, ends = m.global_positions(), m.end_site_positions()
    rpos, rends = rest.global_positions()[0], rest.end_site_positions()[0]
    sites = list(m.skeleton.layout.end_sites)
    out = {}
    for side in ("Left", "Right"):
        for p in FOOT_POINTS:
            j = m.skeleton.index(side + p)
            out[side + p] = (pos[:, j], float(rpos[j, 2]))
        k = sites.index(m.skeleton.index(side + "ToeBase"))
        out[side + "ToeTip"] = (ends[:, k], float(rends[k, 2]))
    return out


def planted_slides(m: Motion) -> dict[str, float]:
    """Largest horizontal path length over any planted interval, per foot point."""
    out = {}
    for name, (track, rest_z) in _foot_tracks(m).items():
        step = np.linalg.norm(np.diff(track[:, :2], axis=0), axis=1)
        speed = np.concatenate([[0.0], step]) * m.fps
        above = CONTACT_ABOVE_REST[name.removeprefix("Left").removeprefix("Right")]
        planted = (track[:, 2] < rest_z + above) & (speed < CONTACT_SPEED)
        worst, run = 0.0, 0.0
        for i in range(1, m.num_frames):
            run = run + step[i - 1] if planted[i] and planted[i - 1] else 0.0
            worst = max(worst, run)
        out[name] = worst
    return out


def range_violations(m: Motion) -> list[str]:
    rv = np.degrees(quat_log(m.rotations))  # (T, J, 3) rotation vectors
    bad = []
    for j, name in enumerate(m.skeleton.names[1:], start=1):
        kind = name.removeprefix("Left").removeprefix("Right")
        angle = np.linalg.norm(rv[:, j], axis=-1).max()
        if angle > MAX_ANGLE[kind]:
            bad.append(f"{name}: {angle:.0f} deg > {MAX_ANGLE[kind]}")
        if kind in HINGES:
            flex = rv[:, j] @ HINGES[kind]
            off = np.linalg.norm(rv[:, j] - np.outer(flex, HINGES[kind]), axis=-1).max()
            if flex.min() < -1.0 or off > 1.0:
                bad.append(f"{name}: hinge flex min {flex.min():.1f}, off-axis {off:.1f} deg")
    return bad


def test_clip_set_and_skeleton(clips: dict[str, Motion]) -> None:
    expected = {"guard", "step_forward", "step_back", *ATTACK_CLIPS, "sway", "step_back_1",
                "step_back_2", "step_left", "step_right", "step_forward_react", *FALLS}  # fmt: skip
    assert set(clips) == expected == set(CLIP_INFO)
    skel = synthetic_skeleton()
    assert skel.layout.unit == "cm" and skel.layout.up == "y"
    assert skel.layout.channels[0] == (
        "Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation",
    )  # fmt: skip
    assert all(ch == ("Zrotation", "Xrotation", "Yrotation") for ch in skel.layout.channels[1:])
    assert len(skel.layout.end_sites) == 5
    parts = map_body_parts(skel)  # the CMU/Mixamo names must map onto every body part
    assert skel.names[parts.joint_of("chest")] == "Spine1"
    for m in clips.values():
        assert m.skeleton == skel


@pytest.mark.parametrize("name", sorted(CLIP_INFO))
def test_clip_plausible(clips: dict[str, Motion], name: str) -> None:
    m = clips[name]
    assert m.name == name
    assert m.fps >= 60.0
    assert 2.0 <= m.duration <= 6.0
    pts = _points(m)
    assert pts[..., 2].min() >= -0.01, f"{name}: a point is {pts[..., 2].min():.3f} m underground"
    slides = planted_slides(m)
    assert max(slides.values()) < MAX_SLIDE, f"{name}: planted foot slides {slides}"
    assert not range_violations(m), f"{name}: {range_violations(m)}"
    if name not in FALLS:
        # everything else is upright throughout and ends standing in guard
        assert pts[..., 2].max(axis=1).min() > 1.5
    assert np.all(np.abs(np.diff(pts, axis=0)).max(axis=(1, 2)) * m.fps < 12.0), "teleport"


def test_guard_size_and_loops(clips: dict[str, Motion]) -> None:
    g = clips["guard"]
    assert 1.65 <= g.height() <= 1.85
    assert 1.65 <= _points(g)[..., 2].max(axis=1).mean() <= 1.85
    np.testing.assert_allclose(_points(g)[0], _points(g)[-1], atol=1e-9)
    assert np.ptp(_points(g), axis=0).max() > 0.005  # it does breathe


@pytest.mark.parametrize("name", sorted(set(CLIP_INFO) - set(FALLS)))
def test_starts_and_ends_in_guard(clips: dict[str, Motion], name: str) -> None:
    # local joint rotations match the guard's (steps end displaced, but in the same pose)
    g0 = clips["guard"].rotations[0]
    m = clips[name]
    for frame in (0, -1):
        dot = np.abs(np.sum(m.rotations[frame, 1:] * g0[1:], axis=-1))
        assert dot.min() > np.cos(np.radians(1.0) / 2), f"{name} frame {frame} is not guard"


@pytest.mark.parametrize("name", ATTACK_CLIPS)
def test_attack_reaches_forward(clips: dict[str, Motion], name: str) -> None:
    m = clips[name]
    pos, ends = m.global_positions(), m.end_site_positions()
    sites = list(m.skeleton.layout.end_sites)
    reach = []
    for joint in STRIKERS[name]:
        j = m.skeleton.index(joint)
        reach.append(pos[:, j, 0])
        if j in sites:
            reach.append(ends[:, sites.index(j), 0])
    peak = np.max(reach) - m.root_positions[0, 0]
    assert 0.8 <= peak <= 1.2, f"{name}: striker reaches {peak:.2f} m forward"


@pytest.mark.parametrize("name", FALLS)
def test_falls_end_lying(clips: dict[str, Motion], name: str) -> None:
    m = clips[name]
    pts = _points(m)
    assert 0.08 <= m.root_positions[-1, 2] <= 0.2
    assert pts[-1, :, 2].max() < 0.6  # everything low: lying, not sitting
    assert pts[-1, :, 2].min() < 0.03  # and on the floor, not floating


def test_each_fall_direction_has_a_fall_as_quick_as_a_knocked_down_body(
    clips: dict[str, Motion],
) -> None:
    # The simulated bodies the real recipients' pushes knock down lie 0.4-0.7 s after they
    # start to go down; with only the 4.5 s falls (lying 1.2-2.2 s in) the search matched a
    # falling body to a lying hold, and the final blend dragged it through the clip's slow fall.
    lying_after = {}
    for name in FALLS:
        m = clips[name]
        pelvis = m.global_positions()[:, map_body_parts(m.skeleton).joint_of("pelvis"), 2]
        lying_after[name] = np.argmax(pelvis <= 0.2) / m.fps
    for way in ("forward", "backward", "sideways"):
        quickest = min(t for n, t in lying_after.items() if n.startswith(f"fall_{way}"))
        assert quickest <= 1.0, f"no {way} fall lies within 1 s: {lying_after}"


def test_a_fall_lies_on_either_side(clips: dict[str, Motion]) -> None:
    # Bodies pushed from the left in simulation lie on their right side; the left-lying sideways
    # fall alone left them a fall on the other side (docs/benchmarks.md)
    sides = set()
    for name in FALLS:
        m = clips[name]
        hips = m.global_positions()[
            -1, [m.skeleton.index("LeftUpLeg"), m.skeleton.index("RightUpLeg")], 2
        ]
        if abs(hips[0] - hips[1]) > 0.12:  # one hip well above the other: lying on a side
            sides.add("left" if hips[0] < hips[1] else "right")
    assert sides == {"left", "right"}, f"falls lie only on the {sides} side"


def test_reproducible(clips: dict[str, Motion]) -> None:
    again = synthetic_clips()
    for name, m in clips.items():
        np.testing.assert_array_equal(again[name].rotations, m.rotations)
        np.testing.assert_array_equal(again[name].root_positions, m.root_positions)


def test_committed_files_match_generator(clips: dict[str, Motion]) -> None:
    from reactmocap.library.bvh import read_bvh

    files = sorted(SYNTHETIC.glob("*.bvh"))
    assert {f.stem for f in files} == set(clips), (
        "regenerate: reactmocap synth data/synthetic_clips"
    )
    for f in files:
        disk, gen = read_bvh(f), clips[f.stem]
        assert disk.num_frames == gen.num_frames and disk.fps == pytest.approx(gen.fps)
        err = np.abs(_points(disk) - _points(gen)).max()
        assert err < 1e-4, f"{f.name} differs from the generator by {err:.2e} m"
    assert (SYNTHETIC / "README.md").read_text().count("SYNTHETIC") >= 1


def test_write_library(tmp_path: Path) -> None:
    from reactmocap.library.bvh import read_bvh

    paths = write_synthetic_library(tmp_path / "lib", fps=60.0)
    assert sorted(p.name for p in paths) == sorted(f"{n}.bvh" for n in CLIP_INFO)
    m = read_bvh(paths[0])
    assert m.skeleton.names == synthetic_skeleton().names


@pytest.mark.parametrize("fps", ["0", "nan", "-30"])
def test_synth_refuses_a_bad_frame_rate_and_makes_no_folder(
    fps: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: 0 left an empty folder behind, nan a ValueError traceback
    from reactmocap.cli import main

    assert main(["synth", str(tmp_path / "clips"), "--fps", fps]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("reactmocap: error: fps must be a positive frame rate") and fps in err
    assert not (tmp_path / "clips").exists()

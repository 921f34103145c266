"""Character construction, Motion <-> MuJoCo state mapping, FK agreement, kinematic contact."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from reactmocap.errors import SimulationError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_from_yaw, quat_mul
from reactmocap.sim import (
    BALL_JOINTS,
    SIM_BODIES,
    World,
    build_character,
    first_contact,
    push_clip,
    track_clip,
)

SHARED = Path(__file__).resolve().parents[2] / ".." / "shared" / "mocap"


def test_structure_is_51_dof(guard: Motion) -> None:
    ch = build_character(guard)
    m = ch.model
    assert m.nv == 51 and m.nq == 67 and m.nbody == 1 + 16
    assert len(SIM_BODIES) == 16 and len(BALL_JOINTS) == 15
    assert sum(ch.segment_masses().values()) == pytest.approx(75.0, rel=1e-9)


def test_roundtrip_motion_qpos_motion(step_forward: Motion) -> None:
    """Motion -> qpos -> Motion on the original skeleton reproduces every joint's global
    position and rotation (non-simulated joints come from the reference)."""
    ch = build_character(step_forward)
    q = ch.qpos_from_motion(step_forward)
    back = ch.motion_from_qpos(q, step_forward.fps, reference=step_forward)
    pa, ra = step_forward.forward_kinematics()
    pb, rb = back.forward_kinematics()
    assert np.abs(pa - pb).max() < 1e-9
    assert np.abs(np.abs(np.sum(ra * rb, axis=-1)) - 1.0).max() < 1e-9


def test_mujoco_fk_agrees_with_library(step_forward: Motion) -> None:
    ch = build_character(step_forward)
    for frame in (0, step_forward.num_frames // 2, step_forward.num_frames - 1):
        assert ch.check_fk(step_forward, frame) < 1e-6


def test_fk_mismatch_is_diagnosed(guard: Motion) -> None:
    """Rotate a folded joint (the clavicle, not simulated): the check names the body, the
    distance and the folded joint."""
    ch = build_character(guard)
    j = guard.skeleton.index("LeftShoulder")
    rot = np.array(guard.rotations)
    rot[:, j] = quat_mul(quat_from_yaw(0.3), rot[:, j])
    bent = guard.replace(rotations=rot)
    with pytest.raises(SimulationError, match=r"mm.*l_upper_arm.*LeftShoulder"):
        ch.check_fk(bent, 0)


def test_velocities_match_finite_differences(step_forward: Motion) -> None:
    """qvel integrated over one frame interval reproduces the next frame's qpos (forward
    differences at the first frame)."""
    import mujoco

    ch = build_character(step_forward)
    q = ch.qpos_from_motion(step_forward, [0, 1])
    v = ch.qvel_from_motion(step_forward, [0])[0]
    nxt = q[0].copy()
    mujoco.mj_integratePos(ch.model, nxt, v, 1.0 / step_forward.fps)
    assert np.abs(nxt - q[1]).max() < 1e-9


def _shared_clips() -> list[Path]:
    return sorted(SHARED.glob("*/*.bvh")) if SHARED.is_dir() else []


@pytest.mark.parametrize("path", _shared_clips() or [None], ids=lambda p: p.name if p else "none")
def test_fk_on_shared_clips_first_frame(path: Path | None) -> None:
    if path is None:
        pytest.skip(f"no shared clips at {SHARED.resolve()}")
    from reactmocap.library import bvh

    motion = bvh.read_bvh(path)
    ch = build_character(motion)
    assert ch.check_fk(motion, 0) < 1e-3
    q = ch.qpos_from_motion(motion, [0])
    back = ch.motion_from_qpos(q, motion.fps, reference=motion.slice(0, 1))
    assert np.abs(back.global_positions() - motion.slice(0, 1).global_positions()).max() < 1e-6


def _approach(guard: Motion, gap0: float, speed: float) -> tuple[Motion, Motion]:
    """Character 0 stands in guard at the origin facing +X; character 1 faces it and walks
    (slides) toward it at ``speed`` m/s from ``gap0`` m away."""
    b = guard.transformed(yaw=np.pi, translation=(gap0, 0.0, 0.0))
    shift = np.zeros((guard.num_frames, 3))
    shift[:, 0] = -speed * guard.times
    return guard, b.replace(root_positions=b.root_positions + shift)


def test_first_contact_and_rewind(guard: Motion) -> None:
    ch = build_character(guard)
    world = World([ch, ch])
    a, b = _approach(guard, 1.6, 0.5)
    hit = first_contact(world, [a, b], fps=30.0)
    assert hit is not None
    assert hit.rewind_frame == hit.frame - 1 and hit.rewind_time < hit.time
    assert 0.3 < hit.time < 3.0 and hit.pairs
    # consistency: in contact at the found frame, not at the rewind frame, with a margin of 0
    again = first_contact(world, [a, b], fps=30.0, start=hit.rewind_time, end=hit.rewind_time)
    assert again is None
    # far apart and not moving: no contact at all
    far_a, far_b = _approach(guard, 3.0, 0.0)
    assert first_contact(world, [far_a, far_b], fps=30.0) is None


def test_track_and_push_functions(guard: Motion) -> None:
    tracked = track_clip(guard, seconds=0.5, root_assist=0.0)
    out, rep, res = tracked.motion, tracked.report, tracked.rollout
    assert out.skeleton is guard.skeleton and out.num_frames == res.times.size
    for key in ("mean_joint_error_rad", "root_error_m", "wall_s", "realtime_factor"):
        assert np.isfinite(getattr(rep, key))
    assert rep.mean_joint_error_rad < 0.2 and not rep.fell
    rep2 = push_clip(
        guard, time=0.2, body="chest", force=(-400.0, 0.0, 0.0), duration=0.1, seconds=0.6
    ).report
    assert rep2.impacts == 1 and rep2.root_error_m > rep.root_error_m


@pytest.fixture(scope="module")
def bvh_clip(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from reactmocap.library import bvh
    from reactmocap.library.synth import synthetic_clips

    path = tmp_path_factory.mktemp("clips") / "guard.bvh"
    bvh.write_bvh(synthetic_clips(30.0)["guard"], path)
    return path


def test_cli_track_and_push(
    bvh_clip: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from reactmocap.cli import main

    out, report = tmp_path / "t.bvh", tmp_path / "t.json"
    assert (
        main(
            ["track", str(bvh_clip), "--seconds", "0.5", "--out", str(out), "--report", str(report)]
        )
        == 0
    )
    data = json.loads(report.read_text())
    for key in ("fell", "mean_joint_error_rad", "root_error_m", "wall_s", "realtime_factor"):
        assert key in data
    for key in ("mean_joint_error_rad", "root_error_m", "wall_s", "realtime_factor"):
        assert np.isfinite(data[key])
    assert data["infeasible_single_support_s"] == 0.0  # a two-footed stance
    assert out.stat().st_size > 0
    pushed = tmp_path / "p.bvh"
    assert (
        main(
            [
                "push",
                str(bvh_clip),
                "--time",
                "0.3",
                "--body",
                "chest",
                "--force=-300,0,0",
                "--duration",
                "0.1",
                "--seconds",
                "0.6",
                "--out",
                str(pushed),
                "--report",
                str(report),
            ]
        )
        == 0
    )
    assert pushed.stat().st_size > 0
    # the push's report says how the body stands at the end, not only that it is upright
    at_end = json.loads(report.read_text())["at_end"]
    assert at_end["judged_as"] == "stand"  # the guard clip stands
    assert at_end["com_speed_m_s"] >= 0.0 and at_end["lowest_sole_m"] < 0.05
    assert (at_end["why"] == "") == at_end["recovered"]
    assert "at the end: " in capsys.readouterr().out
    assert (
        main(
            [
                "push",
                str(bvh_clip),
                "--time",
                "0.3",
                "--body",
                "tail",
                "--force",
                "1,0,0",
                "--out",
                str(tmp_path / "x.bvh"),
            ]
        )
        == 2
    )


def test_cli_push_judges_a_walk_by_its_clip(shared_mocap_dir: Path, tmp_path: Path) -> None:
    """A pushed walk's report judges it by walking as its clip does at the end, not by standing
    still (a walk is never still)."""
    from reactmocap.cli import main

    clip = shared_mocap_dir / "dataset-1_walk_normal_001.bvh"
    if not clip.is_file():
        pytest.skip(f"{clip.name} not in {shared_mocap_dir}")
    report = tmp_path / "w.json"
    args = ["push", str(clip), "--time", "2.0", "--body", "chest", "--force=0,200,0"]
    args += ["--duration", "0.2", "--seconds", "3.0", "--out", str(tmp_path / "w.bvh")]
    assert main([*args, "--report", str(report)]) == 0
    at_end = json.loads(report.read_text())["at_end"]
    assert at_end["judged_as"] == "walk"
    assert 0.5 < at_end["speed_ratio"] < 1.5  # a walk tracked on, not a stand
    assert (at_end["why"] == "") == at_end["recovered"]

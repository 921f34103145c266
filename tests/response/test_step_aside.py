"""The physical mode's attacker steps aside from the recipient's tail in steps: its planted
feet stay where they stand (``final._side_steps``), and the report measures and warns of the
attacker's foot skate."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reactmocap import metrics as qm
from reactmocap.library.bodyparts import map_body_parts
from reactmocap.library.bvh import read_bvh
from reactmocap.library.motion import Motion
from reactmocap.library.placement import ground_root
from reactmocap.response import final


def _added_travel(before: Motion, after: Motion, feet: list[int]) -> float:
    """Horizontal travel (m) that ``after`` adds to the feet planted in ``before`` (as
    :func:`reactmocap.metrics.planted` finds them) while they stay on the ground."""
    a = before.global_positions()[:, feet]
    b = after.global_positions()[:, feet]
    low = np.abs(b - a)[..., 2] < qm.PLANT_HEIGHT_M
    on = qm.planted(a, before.fps) & low[1:] & low[:-1]
    return float(np.linalg.norm(np.diff((b - a)[..., :2], axis=0), axis=-1)[on].sum())


@pytest.mark.parametrize(
    ("clip", "start", "stop"),
    [("walk_normal_001", 0.5, 3.0), ("bow_normal_001", 0.0, 3.0), ("kick_normal_001", 0.0, 2.0)],
)
def test_the_attacker_steps_aside_on_planted_feet(
    shared_mocap_dir: Path, clip: str, start: float, stop: float
) -> None:
    # a real walk, a real bow (standing) and the real kick moved 0.5 m sideways at a side
    # step's pace: the whole-body slide this replaced dragged their planted feet 0.47, 1.0 and
    # 1.0 m (and foot_skate_m, which counts no foot faster than 0.5 m/s, missed it)
    m = read_bvh(shared_mocap_dir / f"dataset-1_{clip}.bvh")
    parts = map_body_parts(m.skeleton)
    m = ground_root(m.slice(round(start * m.fps), round(stop * m.fps)), parts)
    offset = np.clip((m.times - 0.3) * final.STEP_M / final.STEP_S, 0.0, 0.5)
    side = np.array([0.0, 1.0, 0.0])
    speed = qm.joint_speed_max_m_s(m)
    out = final._side_steps(m, parts, offset, side, speed)
    feet = [parts.joint_of(f"{s}_foot") for s in ("l", "r")]
    assert _added_travel(m, out, feet) <= 0.01
    moved = out.root_positions - m.root_positions
    assert moved[-1, 1] == pytest.approx(0.5) and np.abs(moved[:, 0]).max() < 1e-9
    assert qm.speed_ratio(out, m) <= 1.5
    assert qm.foot_skate_m(out, parts) <= qm.foot_skate_m(m, parts) + 0.05
    # the feet went along: at least one foot stepped the whole way
    shift = (out.global_positions()[-1, feet] - m.global_positions()[-1, feet])[:, 1]
    assert shift.max() == pytest.approx(0.5, abs=0.01)


def test_the_attackers_blend_back_keeps_its_planted_feet_and_a_slide_is_warned(
    shared_mocap_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # bench_reactions' real bow kicked by the real kick, blend mode: blending the kicker back
    # from its simulation to its clip slid its planted feet 0.47 m before they were pinned
    # (final._attacker_output's lock_feet)
    from reactmocap.response.pipeline import run_response
    from tests.response.test_pipeline import _bench_kick

    scenario = _bench_kick(shared_mocap_dir, tmp_path, "dataset-1_bow_normal_001",
                           167.42333060441473, (0.9101249775269609, 0.24847072154800792),
                           mode="blend")  # fmt: skip
    rep = run_response(scenario).report
    skate = rep["quality"]["attacker_foot_skate_m"]
    assert 0.0 < skate <= 0.2
    assert "the attacker's planted feet slide" not in " ".join(rep["warnings"])
    lift = rep["quality"]["attacker_lift_m"]
    assert lift is not None and lift >= 0.0
    lifted = "higher off the floor than its clip" in " ".join(rep["warnings"])
    assert lifted == (lift > qm.WARN_ATTACKER_LIFT_M)
    # the warnings themselves, on the same real output with the thresholds under its figures
    monkeypatch.setattr(qm, "WARN_ATTACKER_FOOT_SKATE_M", 0.5 * skate)
    monkeypatch.setattr(qm, "WARN_ATTACKER_LIFT_M", lift - 0.01)
    rep = run_response(scenario).report
    assert f"the attacker's planted feet slide {skate:.2f} m" in " ".join(rep["warnings"])
    assert f"the attacker's body is {lift:.2f} m higher" in " ".join(rep["warnings"])


def test_an_attacker_knocked_off_its_feet_falls_to_the_floor_after_its_simulation() -> None:
    # Simulation 2 can end with the attacker in the air (the real respond kicked: its kicker
    # lying 0.4-0.5 m up); its last pose, held after, falls under gravity onto the floor
    from tests.conftest import SYNTHETIC

    m = read_bvh(SYNTHETIC / "front_kick.bvh")
    parts = map_body_parts(m.skeleton)
    sim = m.replace(root_positions=m.root_positions + np.array([0.0, 0.0, 0.5]))  # 0.5 m up
    lowest = float(sim.slice(-1).global_positions()[0, :, 2].min())
    after = np.linspace(-0.2, 1.0, 37)  # seconds past the simulation's end
    held = sim.sample(np.clip(sim.duration + after, 0.0, sim.duration))
    out = final._falling_when_held(held, after, sim, parts)
    low = out.global_positions()[..., 2].min(axis=1)
    assert np.allclose(low[after <= 0.0], lowest)  # the simulation itself is kept
    fall = np.sqrt(2.0 * lowest / final.STANDARD_GRAVITY)  # from rest: it was held still
    assert low[after >= fall + 0.05] == pytest.approx(0.0, abs=1e-6)  # then on the floor
    k = int(np.argmin(np.abs(after - 0.5 * fall)))
    assert low[k] == pytest.approx(lowest - 0.5 * final.STANDARD_GRAVITY * after[k] ** 2, abs=1e-6)


def test_a_knocked_down_attacker_stays_down_rather_than_rising_through_the_air(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # bench_reactions' real respond kicked (physical mode): its kicker falls in Simulation 2;
    # blended back to its standing kick clip it rose through poses with no foot on the floor
    # (attacker_lift_m 0.37 m); it now stays on the floor where it fell
    from reactmocap.response.pipeline import run_response
    from tests.response.test_pipeline import _bench_kick

    scenario = _bench_kick(
        shared_mocap_dir,
        tmp_path,
        "dataset-1_respond_normal_001",
        156.77102981087745,
        (0.9574638453360457, 0.11494155034128856),
    )
    res = run_response(scenario)
    q = res.report["quality"]
    assert q["attacker_lift_m"] <= qm.WARN_ATTACKER_LIFT_M
    parts = map_body_parts(res.attacker.skeleton)
    pelvis = res.attacker.global_positions()[:, parts.joint_of("pelvis"), 2]
    assert pelvis[-1] < 0.5 * pelvis[0]  # down at the end, as its simulation left it

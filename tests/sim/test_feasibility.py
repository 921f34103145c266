"""Single-support feasibility: a physically simulated motion passes it, the same poses played
faster do not, the shared kick's spinning back kicks are flagged and the walks are not."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.sim import support_feasibility, track_clip

SHARED = Path(__file__).resolve().parents[3] / "shared" / "mocap"


@pytest.fixture(scope="module")
def simulated_step(step_forward: Motion) -> Motion:
    """A physical motion: the whole-body tracker's step, recorded at the clip's rate."""
    tracked = track_clip(step_forward, seconds=step_forward.duration, record_fps=30.0)
    sim, rep = tracked.motion, tracked.report
    assert not rep.fell
    return sim


def test_a_simulated_motion_is_feasible(simulated_step: Motion) -> None:
    check = support_feasibility(simulated_step)
    single = check.single_support
    assert single.sum() >= 5  # the step has a single-support phase to check
    assert np.all(np.isnan(check.residual[~single])) and np.all(check.foot[~single] == -1)
    assert not check.infeasible(2.0).any()
    assert check.stretches() == []


def test_the_same_poses_played_faster_are_not(simulated_step: Motion) -> None:
    # 3x the speed: 9x the accelerations through the same single-support poses
    fast = support_feasibility(simulated_step.replace(fps=3 * simulated_step.fps))
    slow = support_feasibility(simulated_step)
    single = slow.single_support
    assert np.array_equal(fast.single_support, single)
    assert np.median(fast.residual[single]) > 3 * np.median(slow.residual[single])
    assert fast.infeasible(2.0).any()


def test_bad_input_rejected(step_forward: Motion, simulated_step: Motion) -> None:
    with pytest.raises(ConfigError, match="3 frames"):
        support_feasibility(step_forward.slice(0, 2))
    with pytest.raises(ConfigError, match="factor"):
        support_feasibility(simulated_step).infeasible(-1.0)
    with pytest.raises(ConfigError, match="reach"):
        support_feasibility(simulated_step, reach=-0.01)


@pytest.mark.skipif(not SHARED.is_dir(), reason=f"shared mocap not found at {SHARED}")
def test_the_kicks_spins_are_flagged_and_the_walk_is_not() -> None:
    from reactmocap.library.bvh import read_bvh

    kick = sorted(SHARED.glob("*/*kick_normal_001.bvh"))
    walk = sorted(SHARED.glob("*/*walk_normal_001.bvh"))
    if not kick or not walk:
        pytest.skip(f"kick_normal_001 / walk_normal_001 not under {SHARED}")
    check = support_feasibility(read_bvh(kick[0]))
    spins = check.stretches(2.0, 0.3)
    # measured: 1.80-2.47, 6.10-6.87 and 10.67-11.20 s
    assert len(spins) == 3
    for (a, b), t in zip(spins, (2.2, 6.5, 11.0)):
        assert a < t < b
    # the tracking benchmark's window at 2.0 s lies in the first spin
    assert check.infeasible_seconds(2.0, 1.0) >= 0.3
    assert not support_feasibility(read_bvh(walk[0])).infeasible(2.0).any()


@pytest.fixture(scope="module")
def fast_step(step_forward: Motion) -> Motion:
    """The synthetic step played twice as fast: single support no foot can produce (the
    tracked step's own single support became too short to flag much once the tracker
    re-anchored its ground path)."""
    return step_forward.replace(fps=2 * step_forward.fps)


def test_infeasible_seconds_counts_the_frames(fast_step: Motion) -> None:
    fast = support_feasibility(fast_step)
    bad = fast.infeasible(2.0)
    assert bad.any() and fast.infeasible_seconds() == pytest.approx(bad.sum() / fast.fps)
    a, b = fast.stretches(2.0, 0.0)[0]
    assert fast.infeasible_seconds(a, b - a) == pytest.approx(b - a)
    assert fast.infeasible_seconds(0.0, a) == 0.0
    assert fast.infeasible_seconds(factor=20.0) < fast.infeasible_seconds(factor=2.0)
    for bad_args in ({"start": -1.0}, {"seconds": float("nan")}):
        with pytest.raises(ConfigError, match=next(iter(bad_args))):
            fast.infeasible_seconds(**bad_args)  # type: ignore[arg-type]


def test_cli_track_notes_an_infeasible_span(
    fast_step: Motion, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``track`` reports how much of the span asks for more moment than a foot can give, and
    says so: a step played twice as fast is flagged."""
    import json

    from reactmocap.cli import main
    from reactmocap.library.bvh import read_bvh, write_bvh

    clip = tmp_path / "fast.bvh"
    write_bvh(fast_step, clip)
    fast = read_bvh(clip)
    report = tmp_path / "track.json"
    seconds = 0.5
    assert main(["track", str(clip), "--seconds", str(seconds), "--report", str(report)]) == 0
    data = json.loads(report.read_text())
    expected = support_feasibility(fast).infeasible_seconds(0.0, seconds)
    assert data["infeasible_single_support_s"] == pytest.approx(expected) and expected >= 0.1
    assert f"for {expected:.2f} s of this span" in capsys.readouterr().out


def test_summary_matches_the_arrays(simulated_step: Motion) -> None:
    fast = support_feasibility(simulated_step.replace(fps=3 * simulated_step.fps))
    data = fast.summary(2.0, 0.0)
    single = fast.single_support
    assert data["frames"] == simulated_step.num_frames
    assert data["single_support_fraction"] == pytest.approx(single.mean())
    bad = fast.infeasible(2.0)
    assert data["infeasible_fraction_of_single_support"] == pytest.approx(bad.sum() / single.sum())
    stretches = data["stretches"]
    assert isinstance(stretches, list) and len(stretches) == len(fast.stretches(2.0, 0.0)) > 0
    for st, (a, b) in zip(stretches, fast.stretches(2.0, 0.0)):
        assert (st["start_s"], st["end_s"]) == (round(a, 4), round(b, 4)) and a < b
        rows = slice(round(a * fast.fps), round(b * fast.fps))
        assert st["max_residual_nm"] == float(np.max(fast.residual[rows]))


def test_cli_feasibility(
    step_forward: Motion, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    from reactmocap.cli import main
    from reactmocap.library.bvh import write_bvh

    clip = tmp_path / "step.bvh"
    write_bvh(step_forward, clip)
    report = tmp_path / "feasibility.json"
    assert main(["feasibility", str(clip), "--report", str(report)]) == 0
    data = json.loads(report.read_text())
    assert data["clip"] == "step" and data["frames"] == step_forward.num_frames
    assert 0 < data["single_support_fraction"] < 1
    assert "single support" in capsys.readouterr().out
    bad = tmp_path / "bad.json"
    assert main(["feasibility", str(clip), "--min-seconds", "-1", "--report", str(bad)]) == 2
    assert "--min-seconds" in capsys.readouterr().err and not bad.exists()


def test_cli_track_counts_infeasible_seconds_only_up_to_a_fall(
    shared_mocap_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The bare PD servo falls in the real kick clip at 1.57 s, before its first stretch no
    foot can produce (1.67 s): nothing infeasible was tracked. Before, the report and the note
    counted the 4 s asked for (0.77 s)."""
    import json

    from reactmocap.cli import main

    clip = shared_mocap_dir / "dataset-1_kick_normal_001.bvh"
    report = tmp_path / "track.json"
    args = ["track", str(clip), "--seconds", "4", "--controller", "pd", "--report", str(report)]
    assert main(args) == 0
    data = json.loads(report.read_text())
    assert data["status"] == "fell" and data["fell_at_s"] < 1.66
    assert data["infeasible_single_support_s"] == 0.0
    assert "of this span" not in capsys.readouterr().out

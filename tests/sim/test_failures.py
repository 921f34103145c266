"""A failure is a result: tracking that falls or diverges still writes the motion up to that
moment and a report that says what happened; the command fails only with --strict."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reactmocap.cli import main
from reactmocap.library.bvh import read_bvh, write_bvh
from reactmocap.library.motion import Motion
from reactmocap.sim import track_clip


def test_a_fall_ends_the_run_and_says_when(step_forward: Motion) -> None:
    res = track_clip(step_forward, controller="pd")  # the bare PD servo cannot step
    rep = res.report
    assert rep.status == "fell" and rep.fell and rep.fell_at_s is not None
    assert "fell at" in (rep.reason or "")
    assert res.motion.duration == pytest.approx(rep.fell_at_s, abs=1.0 / 60)
    assert res.motion.duration < step_forward.duration - 0.1
    ok = track_clip(step_forward, seconds=0.5).report  # the whole-body tracker holds it
    assert ok.status == "ok" and ok.reason is None and ok.fell_at_s is None


def test_an_unstable_simulation_writes_what_it_has(
    guard: Motion, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    clip = tmp_path / "guard.bvh"
    write_bvh(guard, clip)
    out, report = tmp_path / "out.bvh", tmp_path / "r.json"
    args = ["track", str(clip), "--seconds", "0.5", "--controller", "pd", "--kp", "1e9"]
    assert main([*args, "--out", str(out), "--report", str(report)]) == 0
    data = json.loads(report.read_text())
    assert data["status"] == "unstable" and "unstable" in data["reason"]
    printed = capsys.readouterr().out
    partial = read_bvh(out)
    assert 1 <= partial.num_frames < 30  # up to the last stable frame
    # the summary says how much was tracked, not the span asked for
    assert "UNSTABLE" in printed and f"{partial.duration:.2f} of 0.50 s tracked" in printed
    assert main([*args, "--out", str(out), "--strict"]) == 3

"""``reactmocap athletics ...``: one smoke test per command, and one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reactmocap.cli import main
from reactmocap.library.bvh import read_bvh


@pytest.mark.parametrize(
    ("args", "keys"),
    [
        (["balance", "--seconds", "0.5", "--push", "30"], ["fell", "max_com_offset_m", "on_both_feet"]),
        (["balance", "--seconds", "0.5", "--step"], ["balanced", "steps"]),
        (["land", "--drop", "0.2", "--body", "female"], ["landed", "fell"]),
        (["leap", "--effort", "0.3"],
         ["achieved_height_m", "fell", "landed", "peak_grf_bw", "time_to_liftoff_s",
          "human_plausible"]),
        (["broad-jump", "--effort", "0.2"], ["achieved_distance_m", "fell", "landed"]),
    ],
)  # fmt: skip
def test_each_command_writes_bvh_and_report(
    args: list[str], keys: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, rep = tmp_path / "m.bvh", tmp_path / "r.json"
    assert main(["athletics", *args, "--out", str(out), "--report", str(rep)]) == 0
    report = json.loads(rep.read_text())
    assert all(k in report for k in keys)
    if "--effort" in args:  # an effort asks no height or distance: not "asked 0.000"
        what = "height" if args[0] == "leap" else "distance"
        assert report[f"commanded_{what}_m"] is None
        assert f"m (effort {args[-1]})" in capsys.readouterr().out
    motion = read_bvh(out)
    assert motion.num_frames > 10 and "LeftUpLeg" in motion.skeleton.names


def test_leap_push_flag_selects_the_push_com_by_default(tmp_path: Path) -> None:
    rep = tmp_path / "r.json"
    args = ["athletics", "leap", "--height", "0.3", "--out", str(tmp_path / "m.bvh")]
    assert main([*args, "--report", str(rep)]) == 0
    report = json.loads(rep.read_text())
    # the report names the push that ran, and the COM push stays under the timed push's force
    assert report["push"] == "com" and report["peak_grf_bw"] < 3.5
    assert abs(report["achieved_height_m"] - 0.3) < 0.03
    assert main([*args, "--push", "timed", "--report", str(rep)]) == 0
    timed = json.loads(rep.read_text())
    assert timed["push"] == "timed" and timed["peak_grf_bw"] > 3.5


def test_bad_input_is_one_line_and_nothing_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "m.bvh"
    for args in (["leap", "--height", "5"], ["leap", "--body", "robot", "--height", "0.3"],
                 ["land", "--drop", "nan"]):  # fmt: skip
        assert main(["athletics", *args, "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("reactmocap: error:")
    assert not out.exists()


@pytest.mark.parametrize("effort", ["5", "-1"])
def test_an_effort_outside_0_1_is_refused(
    effort: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: --effort 5 ran (a 1 m leap past the strength model) though the help says 0-1
    out = tmp_path / "m.bvh"
    for cmd in ("leap", "broad-jump"):
        assert main(["athletics", cmd, "--effort", effort, "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith(f"reactmocap: error: {cmd} effort must be ") and "got" in err
    assert not out.exists()


def test_the_help_lists_every_athletics_command_and_no_empty_notes() -> None:
    # before: the top-level help left out handspring, bicycle and group, and flags without a
    # unit or default read "(; default None)"
    import argparse

    from reactmocap.cli import build_parser

    def subparsers(p: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
        acts = [a for a in p._actions if isinstance(a, argparse._SubParsersAction)]
        return dict(acts[0].choices) if acts else {}

    top = build_parser()
    summary = " ".join(top.format_help().split())
    athletics = subparsers(top)["athletics"]
    for name, p in subparsers(athletics).items():
        assert name in summary.split("athletic controllers:")[1], name
        text = p.format_help()
        assert "(;" not in text and "default None" not in text, name

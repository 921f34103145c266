"""``reactmocap athletics run`` smoke test: BVH, report, plot written, all or nothing."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reactmocap.cli import main
from reactmocap.library.bvh import read_bvh


def test_run_command_writes_bvh_report_plot(tmp_path: Path) -> None:
    out, rep, plot = tmp_path / "run.bvh", tmp_path / "r.json", tmp_path / "p.png"
    argv = ["athletics", "run", "--speed", "3.5", "--seconds", "1.5", "--path", "circle:10",
            "--out", str(out), "--report", str(rep), "--plot", str(plot), "--fps", "30"]  # fmt: skip
    assert main(argv) == 0
    report = json.loads(rep.read_text())
    for key in ("mean_speed_m_s", "speed_error_m_s", "path_error_m", "fell",
                "cadence_steps_s", "stride_m"):  # fmt: skip
        assert key in report
    motion = read_bvh(out)
    assert motion.num_frames == 46
    assert plot.stat().st_size > 1000


def test_run_command_writes_nothing_on_failure(tmp_path: Path) -> None:
    out, rep = tmp_path / "run.bvh", tmp_path / "r.json"
    argv = ["athletics", "run", "--speed", "3.5", "--seconds", "0.2", "--out", str(out),
            "--report", str(rep), "--video", str(tmp_path / "v.avi")]  # fmt: skip
    assert main(argv) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.mark.parametrize("cmd", [["run", "--help"], ["vault", "--help"]])
def test_help(cmd: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["athletics", *cmd])
    assert exc.value.code == 0
    assert "--report" in capsys.readouterr().out

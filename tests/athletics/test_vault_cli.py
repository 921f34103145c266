"""``reactmocap athletics vault`` smoke test."""

from __future__ import annotations

import json
from pathlib import Path

from reactmocap.athletics.vault import TABLE1_KEYS
from reactmocap.cli import main


def test_vault_command_writes_bvh_report_plot(tmp_path: Path) -> None:
    out, rep, plot = tmp_path / "v.bvh", tmp_path / "v.json", tmp_path / "v.png"
    argv = ["athletics", "vault", "--seconds", "1.0", "--out", str(out), "--report", str(rep),
            "--plot", str(plot), "--fps", "30"]  # fmt: skip
    assert main(argv) == 0
    report = json.loads(rep.read_text())
    assert set(report["table1"]) == set(TABLE1_KEYS)
    assert out.stat().st_size > 1000 and plot.stat().st_size > 1000
    # 1 s ends in the second flight: no touchdown, so no rotation at it (it gave the last
    # frame's, 363 deg)
    assert report["touchdown_s"] is None and report["rotation_at_touchdown_deg"] is None
    assert not report["landed"] and report["notes"]

"""``benchmarks/bench_push.py``: a clip that falls unpushed is recorded, not a crash; bad ``--params``
are refused before any run."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import pytest


def test_the_push_benchmark_records_a_clip_that_falls_unpushed(
    load_bench: Callable[[str], ModuleType], shared_mocap_dir: Path, tmp_path: Path
) -> None:
    del shared_mocap_dir  # the benchmark reads the shared clips itself
    bench = load_bench("bench_push")
    out = tmp_path / "push.json"
    # the plan held to 5 N m per joint cannot stand the clip: there is no push to measure (the
    # --forces sweep used to crash on it with a TypeError, 2026-12-06)
    args = ["--only", "standing", "--after", "1.0", "--forces", "50", "--dirs", "front",
            "--jobs", "1", "--params", '{"torque_limit": 5.0}', "--json", str(out)]  # fmt: skip
    assert bench.main(args) == 0
    row = json.loads(out.read_text())["standing"]
    assert row["falls_unpushed"] is True and row["clip"] == "bye_normal_001"
    assert "survived" not in row and "max_force_n" not in row


def test_the_push_benchmark_refuses_bad_params_before_running(
    load_bench: Callable[[str], ModuleType], capsys: pytest.CaptureFixture[str]
) -> None:
    bench = load_bench("bench_push")
    for bad, says in (('{"nope": 1}', "no parameter 'nope'"), ("{nope", "--params")):
        with pytest.raises(SystemExit) as exit_:
            bench.main(["--params", bad])
        assert exit_.value.code == 2
        assert says in capsys.readouterr().err

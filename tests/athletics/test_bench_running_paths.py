"""The running benchmark's path row (``benchmarks/bench_athletics_running.py --paths``): each
path at several speeds, and a verdict that names the speeds the goal is met at."""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

import pytest


def test_the_path_row_says_met_only_at_the_speeds_that_hold(
    capsys: pytest.CaptureFixture[str], load_bench: Callable[[str], ModuleType]
) -> None:
    # a 10 m circle holds at 3 m/s and falls within 2 s at 3.5 (docs/athletics.md): cut to
    # 5 s (3 s at 2.5 m/s are still the entry's 0.4 m), the verdict must name 3 alone and
    # not call the path goal met
    met = load_bench("bench_athletics_running").paths(speeds=(3.0, 3.5), runs=(("circle:10", 5.0),))
    out = capsys.readouterr().out
    assert met == {"circle:10": [3.0]}
    assert "| circle:10 | 3 | 5 | no |" in out
    assert "| circle:10 | 3.5 | 5 | at 1." in out
    assert "- circle:10: met at 3 m/s only; not at 3.5 (fell at 1." in out
    assert "path goal met at every path and speed: no" in out

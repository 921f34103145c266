"""The athletics benchmark's limit searches (``benchmarks/bench_athletics.py``)."""

from __future__ import annotations

import math
from collections.abc import Callable
from types import ModuleType

from reactmocap.athletics import run
from reactmocap.athletics.scene import DEFAULT_CONTACT


def test_the_contiguous_limit_stops_at_the_first_failure_where_the_bisection_finds_an_island(
    load_bench: Callable[[str], ModuleType],
) -> None:
    bench = load_bench("bench_athletics")
    calls: list[float] = []

    def held(f: float) -> bool:  # held to 160 N, an island at 220-230 N (his front-left's shape)
        calls.append(f)
        return f <= 160.0 or 220.0 <= f <= 230.0

    assert bench._contiguous(held, 0.0, 600.0, 5.0) == 160.0
    assert max(calls) == 165.0  # stepped up to the first failure, no further
    assert bench._largest(held, 0.0, 300.0, 5.0) == 230.0  # the bisection lands on the island
    assert math.isnan(bench._contiguous(lambda f: f > 0.0, 0.0, 600.0, 5.0))
    assert bench._contiguous(lambda f: True, 0.0, 20.0, 5.0) == 20.0


def test_the_push_judge_runs_long_enough_to_see_a_one_foot_stand_fall(
    load_bench: Callable[[str], ModuleType],
) -> None:
    # her 95 N back-left push: still on one foot at 3 s (the 3 s judge held it), down by 5 s
    bench = load_bench("bench_athletics")
    short = run("balance", "female", check_range=False, seconds=3.0, push=95.0,
                push_dir=math.radians(135.0)).report  # fmt: skip
    assert short["balanced"] and not short["on_both_feet"]
    assert bench.PUSH_SECONDS >= 5.0
    assert not bench._push_held("female", 135.0, DEFAULT_CONTACT)(95.0)
    assert bench._push_held("female", 135.0, DEFAULT_CONTACT)(90.0)  # held at 8 s too


def test_the_offset_judge_runs_long_enough_to_see_a_drift_fall(
    load_bench: Callable[[str], ModuleType],
) -> None:
    # his back-left COM offset 0.08 m: still on both feet at 3 s (the 3 s judge held it, the
    # limit was 0.085), the COM drifting back over the heel and falling by 8 s; 0.065 m holds
    bench = load_bench("bench_athletics")
    a = math.radians(135.0)
    short = run("balance", "male", check_range=False, seconds=3.0,
                com_offset_x=0.08 * math.cos(a), com_offset_y=0.08 * math.sin(a)).report  # fmt: skip
    assert short["balanced"] and short["on_both_feet"]
    assert bench.STAND_SECONDS >= 8.0
    assert not bench._offset_held("male", 135.0, DEFAULT_CONTACT)(0.08)
    assert bench._offset_held("male", 135.0, DEFAULT_CONTACT)(0.065)


def test_the_slope_judge_runs_long_enough_to_see_the_feet_creep(
    load_bench: Callable[[str], ModuleType],
) -> None:
    # his sideways slope at 22.5 deg: still on both feet at 3 s, the feet creeping downhill
    # and the stance narrowing until he falls (about 6 s); the supported range (--tables)
    # keeps the library's default 3 s run
    bench = load_bench("bench_athletics")
    assert bench.TABLE_SLOPE_SECONDS == 3.0
    assert bench._slope_held("male", 90.0, DEFAULT_CONTACT, bench.TABLE_SLOPE_SECONDS)(22.5)
    assert not bench._slope_held("male", 90.0, DEFAULT_CONTACT, bench.STAND_SECONDS)(22.5)

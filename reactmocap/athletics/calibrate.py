"""Building the measured tables (:mod:`reactmocap.athletics.tables`) and the supported ranges:
run a behaviour over a grid of efforts or inputs and keep what was achieved. The benchmark
(``benchmarks/bench_athletics.py --tables``) calls these and writes
``reactmocap/athletics/measured.py``."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from reactmocap.io import atomic_write_text

__all__ = ["contiguous_range", "effort_table", "sweep", "write_measured"]


def _one(job: tuple[str, str, dict[str, Any]]) -> dict[str, Any]:
    from reactmocap.athletics.behaviours import run

    name, body, params = job
    report = run(name, body, check_range=False, **params).report
    return {**params, **report}


def sweep(
    name: str, body: str, grid: Iterable[dict[str, Any]], workers: int = 1
) -> list[dict[str, Any]]:
    """Run ``name`` on ``body`` once per parameter dict (range checks off); the reports with
    their parameters, in grid order. ``workers`` > 1 runs them in processes."""
    jobs = [(name, body, dict(p)) for p in grid]
    if workers <= 1:
        return [_one(j) for j in jobs]
    with ProcessPoolExecutor(workers) as ex:
        return list(ex.map(_one, jobs))


def effort_table(
    rows: Sequence[dict[str, Any]], key: str, ok: Callable[[dict[str, Any]], bool]
) -> tuple[tuple[float, float], ...]:
    """``(effort, achieved)`` rows where ``ok`` holds, thinned to the longest run over which
    the achieved value strictly grows with the effort (a longest increasing subsequence), so
    the table can be inverted."""
    pts = sorted((float(r["effort"]), float(r[key])) for r in rows if ok(r))
    if not pts:
        return ()
    best = [1] * len(pts)
    prev = [-1] * len(pts)
    for i in range(len(pts)):
        for j in range(i):
            if pts[j][1] < pts[i][1] and best[j] + 1 > best[i]:
                best[i], prev[i] = best[j] + 1, j
    i = int(np.argmax(best))
    chain = []
    while i >= 0:
        chain.append(pts[i])
        i = prev[i]
    return tuple((round(s, 4), round(v, 4)) for s, v in reversed(chain))


def contiguous_range(
    values: Sequence[float], ok: Sequence[bool], start: float
) -> tuple[float, float] | None:
    """The widest interval around ``start`` of grid ``values`` (sorted) where every ``ok``
    holds; None if ``start``'s own grid point fails."""
    v = np.asarray(values, dtype=np.float64)
    good = np.asarray(ok, dtype=bool)
    i = int(np.argmin(np.abs(v - start)))
    if not good[i]:
        return None
    lo = hi = i
    while lo > 0 and good[lo - 1]:
        lo -= 1
    while hi < v.size - 1 and good[hi + 1]:
        hi += 1
    return float(v[lo]), float(v[hi])


def write_measured(path: Path, values: dict[str, Any], header: str) -> None:
    """Write the measured tables as a Python module of literals (atomic)."""
    lines = [f'"""{header}"""', "", "from __future__ import annotations", "",
             "from typing import Any", ""]  # fmt: skip
    for name, value in values.items():
        kind = "" if isinstance(value, str) else ": dict[Any, Any]"
        lines.append(f"{name}{kind} = {value!r}")
    atomic_write_text(path, "\n".join(lines) + "\n")

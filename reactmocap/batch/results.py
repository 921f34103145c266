"""Result rows of a batch: how a response report becomes a row, the append-only
``results.jsonl`` store that makes sweeps resumable, the ``results.csv`` view and the summary.

``results.jsonl`` is the source of truth. Each row is one ``os.write`` of a whole line followed
by ``fsync``, so a killed run leaves at most one partial trailing line, which the next load
truncates. ``results.csv`` is regenerated from it atomically.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from reactmocap.io import atomic_write_text

__all__ = [
    "QUALITY_METRICS",
    "TIMING_COLUMNS",
    "MetricStats",
    "ResultStore",
    "Summary",
    "error_row",
    "format_summary",
    "metric_columns",
    "ordered_rows",
    "report_row",
    "row_columns",
    "summarize",
]

#: the response report's ``quality`` keys (reactmocap.metrics), in the issue's order
QUALITY_METRICS = (
    "match_distance",
    "blend_root_offset_max_m",
    "blend_joint_correction_max_rad",
    "blend_root_turn_max_rad",
    "stitch_velocity_jump_rad_s",
    "foot_skate_m",
    "penetration_max_m",
    "fell",
    "intended_fall",
    "reaction_displacement_m",
    "reaction_direction_error_deg",
    "transition_s",
    "contact_impulse_Ns",
    "character_overlap_max_m",
    "attacker_speed_ratio",
    "attacker_foot_skate_m",
    "attacker_lift_m",
    "warnings",
)
TIMING_STAGES = ("scan", "sim1", "search", "sim2", "blend", "total")
TIMING_COLUMNS = tuple(f"time_{s}_s" for s in TIMING_STAGES)
_HEAD = ("status", "error", "matched_clip", "matched_frame", "distance")
#: errors are kept to one readable line in the tables
MAX_ERROR_CHARS = 500


def row_columns(axes: Sequence[str], *, output_dir: bool = False) -> list[str]:
    cols = ["id", *axes, *_HEAD, *QUALITY_METRICS, *TIMING_COLUMNS]
    return [*cols, "output_dir"] if output_dir else cols


def metric_columns() -> list[str]:
    """Numeric columns that the summary and the regression look at."""
    return ["matched_frame", *QUALITY_METRICS, *TIMING_COLUMNS]


def _base(pid: str, params: Mapping[str, Any]) -> dict[str, Any]:
    row: dict[str, Any] = {"id": pid, **params}
    row.update({c: None for c in (*_HEAD, *QUALITY_METRICS, *TIMING_COLUMNS)})
    return row


def report_row(
    pid: str, params: Mapping[str, Any], report: Mapping[str, Any], output_dir: str | None = None
) -> dict[str, Any]:
    row = _base(pid, params)
    matched = report.get("matched", {})
    quality = report.get("quality", {})
    timings = report.get("timings_s", {})
    row.update(
        status="ok",
        matched_clip=matched.get("clip"),
        matched_frame=matched.get("frame"),
        distance=matched.get("distance"),
    )
    row.update({m: _plain(quality.get(m)) for m in QUALITY_METRICS})
    row["warnings"] = len(report.get("warnings", []))
    row.update({f"time_{s}_s": _plain(timings.get(s)) for s in TIMING_STAGES})
    row["matched_frame"] = _plain(row["matched_frame"])
    row["distance"] = _plain(row["distance"])
    if output_dir is not None:
        row["output_dir"] = output_dir
    return row


def error_row(
    pid: str, params: Mapping[str, Any], message: str, output_dir: str | None = None
) -> dict[str, Any]:
    row = _base(pid, params)
    one_line = " ".join(message.split())
    row.update(status="error", error=one_line[:MAX_ERROR_CHARS])
    if output_dir is not None:
        row["output_dir"] = output_dir
    return row


def _plain(v: Any) -> Any:
    """numpy scalars -> Python, so rows are plain JSON."""
    return v.item() if isinstance(v, np.generic) else v


class ResultStore:
    """``DIR/results.jsonl`` (append-only, last row per id wins) and ``DIR/results.csv``."""

    def __init__(self, out_dir: str | Path) -> None:
        self.dir = Path(out_dir)
        self.jsonl = self.dir / "results.jsonl"
        self.csv = self.dir / "results.csv"
        self._fd: int | None = None

    def load(self) -> dict[str, dict[str, Any]]:
        """Rows by id. A partial trailing line (a hard kill mid-write) is truncated away."""
        try:
            data = self.jsonl.read_bytes()
        except FileNotFoundError:
            return {}
        end = data.rfind(b"\n") + 1
        if end < len(data):
            os.truncate(self.jsonl, end)
            data = data[:end]
        rows: dict[str, dict[str, Any]] = {}
        for line in data.splitlines():
            try:
                row = json.loads(line)
            except json.JSONDecodeError:
                continue  # cannot happen with whole-line writes; never fatal for a resume
            if isinstance(row, dict) and "id" in row:
                rows[row["id"]] = row
        return rows

    def append(self, row: Mapping[str, Any]) -> None:
        if self._fd is None:
            self.dir.mkdir(parents=True, exist_ok=True)
            self._fd = os.open(self.jsonl, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
        data = (json.dumps(row) + "\n").encode()
        written = os.write(self._fd, data)  # one write of the whole line
        while written < len(data):  # only on a full disk or similar; finish the line
            written += os.write(self._fd, data[written:])
        os.fsync(self._fd)

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def write_csv(
        self, order: Sequence[str] = (), axes: Sequence[str] = ()
    ) -> list[dict[str, Any]]:
        """Regenerate results.csv from the jsonl: rows in ``order`` (ids) first, then any others
        (from earlier sweeps into the same folder). Returns the rows written."""
        rows = ordered_rows(self.load(), order)
        with_out = any("output_dir" in r for r in rows)
        cols = row_columns(axes, output_dir=with_out)
        for r in rows:  # parameters of other sweeps into the same folder
            cols.extend(k for k in r if k not in cols)
        buf = io.StringIO()
        w = csv.DictWriter(
            buf, fieldnames=cols, restval="", extrasaction="ignore", lineterminator="\n"
        )
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if v is None else v) for k, v in r.items()})
        atomic_write_text(self.csv, buf.getvalue())
        return rows


def ordered_rows(rows: Mapping[str, dict[str, Any]], order: Sequence[str]) -> list[dict[str, Any]]:
    first = [rows[i] for i in order if i in rows]
    seen = set(order)
    return first + [r for i, r in rows.items() if i not in seen]


@dataclass(frozen=True)
class MetricStats:
    count: int
    median: float
    p95: float
    mean: float

    def to_dict(self) -> dict[str, float]:
        return {"count": self.count, "median": self.median, "p95": self.p95, "mean": self.mean}


@dataclass(frozen=True)
class Summary:
    count: int
    failures: int
    metrics: dict[str, MetricStats]


def _values(rows: Iterable[Mapping[str, Any]], col: str) -> list[float]:
    out = []
    for r in rows:
        v = r.get(col)
        if isinstance(v, bool | int | float) and not (isinstance(v, float) and math.isnan(v)):
            out.append(float(v))
    return out


def summarize(rows: Sequence[Mapping[str, Any]], columns: Sequence[str] | None = None) -> Summary:
    """Count, failures and median/p95/mean of every numeric metric over the ok rows (booleans
    count as 0/1, so their mean is a rate)."""
    ok = [r for r in rows if r.get("status") == "ok"]
    stats = {}
    for col in columns if columns is not None else metric_columns():
        v = _values(ok, col)
        if v:
            a = np.asarray(v)
            stats[col] = MetricStats(
                len(v), float(np.median(a)), float(np.percentile(a, 95)), float(a.mean())
            )
    return Summary(len(rows), sum(r.get("status") != "ok" for r in rows), stats)


def format_summary(s: Summary) -> str:
    lines = [f"{s.count} scenarios, {s.failures} failed"]
    if s.metrics:
        lines.append(f"{'metric':34s} {'n':>5s} {'median':>11s} {'p95':>11s} {'mean':>11s}")
        for name, m in s.metrics.items():
            lines.append(f"{name:34s} {m.count:5d} {m.median:11.4g} {m.p95:11.4g} {m.mean:11.4g}")
    return "\n".join(lines)

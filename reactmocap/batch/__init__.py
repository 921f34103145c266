"""Batch scenario sweeps: expand a sweep file into scenarios, run them on a local process pool
or Ray, collect resumable results, plot them and check them against a regression baseline."""

from reactmocap.batch.plots import contact_sheet, plot_axes, plot_batch
from reactmocap.batch.regress import (
    DEFAULT_TOLERANCES,
    Comparison,
    Tolerance,
    compare,
    format_comparison,
    load_baseline,
    load_results,
    make_baseline,
    regress,
)
from reactmocap.batch.results import (
    QUALITY_METRICS,
    TIMING_COLUMNS,
    ResultStore,
    Summary,
    format_summary,
    summarize,
)
from reactmocap.batch.runners import RUNNERS, BatchResult, Job, describe, get_runner, run_batch
from reactmocap.batch.sweep import (
    ALIASES,
    AXES,
    TABLES,
    Axis,
    Sweep,
    SweepPoint,
    describe_axes,
    load_sweep,
    parse_sweep,
    point_id,
)

__all__ = [
    "ALIASES",
    "AXES",
    "DEFAULT_TOLERANCES",
    "QUALITY_METRICS",
    "RUNNERS",
    "TABLES",
    "TIMING_COLUMNS",
    "Axis",
    "BatchResult",
    "Comparison",
    "Job",
    "ResultStore",
    "Summary",
    "Sweep",
    "SweepPoint",
    "Tolerance",
    "compare",
    "contact_sheet",
    "describe",
    "describe_axes",
    "format_comparison",
    "format_summary",
    "get_runner",
    "load_baseline",
    "load_results",
    "load_sweep",
    "make_baseline",
    "parse_sweep",
    "plot_axes",
    "plot_batch",
    "point_id",
    "regress",
    "run_batch",
    "summarize",
]

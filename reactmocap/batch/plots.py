"""Figures of a results folder: metrics against each swept axis, and a contact sheet of the
saved animations (like the paper's Figure 2) drawn as stick figures with matplotlib.

Every figure is a PNG written atomically into the results folder; matplotlib (the ``plot``
extra) runs on the Agg backend, so no display is needed.
"""

from __future__ import annotations

import json
import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from reactmocap.batch.results import QUALITY_METRICS, ResultStore
from reactmocap.batch.sweep import AXES
from reactmocap.errors import ConfigError
from reactmocap.io import save_png
from reactmocap.response.plots import pyplot

__all__ = ["ANGLE_AXES", "contact_sheet", "plot_axes", "plot_batch"]

#: axes in degrees get polar plots
ANGLE_AXES = ("facing_deg", "force_dir_deg")
POLAR_METRICS = ("match_distance", "blend_joint_correction_max_rad", "blend_root_offset_max_m")
LINE_METRICS = tuple(m for m in QUALITY_METRICS if m not in ("fell", "intended_fall"))


def _load(results_dir: Path) -> tuple[list[dict[str, Any]], dict[str, list[Any]]]:
    rows = list(ResultStore(results_dir).load().values())
    if not rows:
        raise ConfigError(f"{results_dir}: no results to plot (results.jsonl missing or empty)")
    try:
        axes = json.loads((results_dir / "sweep.json").read_text())["axes"]
    except (OSError, ValueError, KeyError):
        axes = {}
    if not axes:  # infer from the row keys that are known axes
        axes = {
            a: sorted({_hashable(r[a]) for r in rows if a in r})
            for a in AXES
            if any(a in r for r in rows)
        }
    return rows, axes


def _hashable(v: Any) -> Any:
    """A vector axis value (a JSON list) as a tuple, so it can group rows."""
    return tuple(_hashable(x) for x in v) if isinstance(v, list) else v


def _categorical(axis: str) -> bool:
    """Names, flags and vectors get bars; numbers get lines."""
    a = AXES.get(axis)
    return a is not None and a.kind not in ("float", "int")


def _by_value(rows: Sequence[Mapping[str, Any]], axis: str, metric: str) -> dict[Any, float]:
    """Median of ``metric`` per value of ``axis`` over ok rows (other axes pooled)."""
    groups: dict[Any, list[float]] = defaultdict(list)
    for r in rows:
        v = r.get(metric)
        if r.get("status") == "ok" and axis in r and isinstance(v, int | float):
            groups[_hashable(r[axis])].append(float(v))
    return {k: float(np.median(v)) for k, v in groups.items()}


def plot_axes(results_dir: str | Path) -> list[Path]:
    """One PNG per swept axis with more than one value: polar for angles, lines for numbers,
    bars for names."""
    d = Path(results_dir)
    rows, axes = _load(d)
    plt = pyplot()
    written = []
    for axis, values in axes.items():
        if len(values) < 2:
            continue
        if axis in ANGLE_AXES or (axis in AXES and AXES[axis].unit == "deg"):
            fig, axs = plt.subplots(
                1,
                len(POLAR_METRICS),
                subplot_kw={"projection": "polar"},
                figsize=(4.6 * len(POLAR_METRICS), 4.6),
                dpi=100,
            )
            for ax, metric in zip(axs, POLAR_METRICS):
                med = _by_value(rows, axis, metric)
                keys = sorted(med)
                if keys:
                    th = np.radians(keys + keys[:1])
                    ax.plot(th, [med[k] for k in keys + keys[:1]], "o-", ms=3)
                ax.set_title(metric, fontsize=9, pad=14)
                ax.tick_params(labelsize=7)
                ax.set_rlabel_position(112.5)  # radial labels between the angle labels
            fig.suptitle(f"{_stem(d)}: median over other axes vs {axis}")
            fig.subplots_adjust(wspace=0.45, top=0.8)
            written.append(save_png(fig, d / f"plot_{axis}.png"))
            continue
        ncol = 3
        nrow = math.ceil(len(LINE_METRICS) / ncol)
        fig, axs = plt.subplots(nrow, ncol, figsize=(4 * ncol, 3 * nrow), dpi=100)
        for ax, metric in zip(np.ravel(axs), LINE_METRICS):
            med = _by_value(rows, axis, metric)
            keys = sorted(med, key=lambda k: (isinstance(k, str), k))
            if _categorical(axis):
                ax.bar(range(len(keys)), [med[k] for k in keys])
                ax.set_xticks(range(len(keys)), [str(k) for k in keys], rotation=30, fontsize=7)
            else:
                ax.plot(keys, [med[k] for k in keys], "o-", ms=3)
                ax.set_xlabel(axis)
            ax.set_title(metric, fontsize=9)
        fig.suptitle(f"{_stem(d)}: median over other axes vs {axis}")
        fig.tight_layout()
        written.append(save_png(fig, d / f"plot_{axis}.png"))
    return written


def _stem(d: Path) -> str:
    return d.resolve().name


def _project(p: np.ndarray, azim_deg: float = -60.0, elev_deg: float = 15.0) -> np.ndarray:
    """Orthographic view of Z-up points from a fixed camera: (..., 3) -> (..., 2)."""
    az, el = math.radians(azim_deg), math.radians(elev_deg)
    right = np.array([-math.sin(az), math.cos(az), 0.0])
    up = np.array([-math.cos(az) * math.sin(el), -math.sin(az) * math.sin(el), math.cos(el)])
    return np.stack([p @ right, p @ up], axis=-1)


def contact_sheet(
    results_dir: str | Path, *, max_scenarios: int = 12, frames: int = 6
) -> Path | None:
    """``DIR/contact_sheet.png``: a row per scenario (evenly picked, grid order) with ``frames``
    stick-figure poses from just before the impact to the end of the output, recipient in blue
    and attacker in red, seen from one fixed camera so that facing changes show. Needs the
    per-scenario animations of ``batch --save-animations``; returns None without them."""
    from reactmocap.library.bvh import read_bvh

    d = Path(results_dir)
    rows, axes = _load(d)
    saved = [
        r for r in rows if r.get("output_dir") and (d / r["output_dir"] / "recipient.bvh").is_file()
    ]
    saved.sort(key=lambda r: [(isinstance(r.get(a), str), r.get(a) or 0) for a in axes])
    if not saved:
        return None
    pick = np.unique(np.linspace(0, len(saved) - 1, min(max_scenarios, len(saved))).round())
    chosen = [saved[int(i)] for i in pick]
    plt = pyplot()
    fig, axs = plt.subplots(
        len(chosen), frames, figsize=(1.6 * frames, 1.9 * len(chosen)), dpi=100, squeeze=False
    )
    for row_axes, r in zip(axs, chosen):
        sdir = d / r["output_dir"]
        figs = [(read_bvh(sdir / "recipient.bvh"), "tab:blue")]
        if (sdir / "attacker.bvh").is_file():
            figs.append((read_bvh(sdir / "attacker.bvh"), "tab:red"))
        t_imp = 0.0
        try:
            t_imp = float(json.loads((sdir / "report.json").read_text())["impact"]["time"])
        except (OSError, ValueError, KeyError, TypeError):
            pass
        rec = figs[0][0]
        times = np.linspace(max(0.0, t_imp - 0.1), rec.duration, frames)
        posed = [(m.forward_kinematics()[0], m.skeleton.parents, m.fps, c) for m, c in figs]
        allp = _project(np.concatenate([g.reshape(-1, 3) for g, *_ in posed]))
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        for ax, t in zip(row_axes, times):
            for g, parents, fps, color in posed:
                f = min(int(round(t * fps)), len(g) - 1)
                p2 = _project(g[f])
                for j, par in enumerate(parents):
                    if par >= 0:
                        ax.plot(*zip(p2[par], p2[j]), color=color, lw=1.2)
            ax.set_xlim(lo[0] - 0.1, hi[0] + 0.1)
            ax.set_ylim(lo[1] - 0.05, hi[1] + 0.1)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(f"{t:.2f} s", fontsize=6)
        label = ", ".join(f"{a}={r.get(a)}" for a in axes)
        row_axes[0].set_ylabel(f"{label}\n{r.get('matched_clip')}", fontsize=6)
    fig.tight_layout()
    return save_png(fig, d / "contact_sheet.png")


def plot_batch(results_dir: str | Path) -> list[Path]:
    """Every figure for a results folder: :func:`plot_axes` and, with saved animations,
    :func:`contact_sheet`."""
    written = plot_axes(results_dir)
    sheet = contact_sheet(results_dir)
    return written + ([sheet] if sheet is not None else [])

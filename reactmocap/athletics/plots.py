"""Figures of athletic runs: one run's COM height and ground force over time with its states
(``--plot``), the thesis-style commanded-against-achieved plots with the diagonal, and a video
(MuJoCo's renderer, or the stick figure where no GL context exists). Written atomically."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from reactmocap.athletics.report import ground_force
from reactmocap.io import save_png
from reactmocap.response.plots import pyplot

if TYPE_CHECKING:
    from reactmocap.athletics.behaviours import AthleticsResult

__all__ = ["commanded_plot", "run_plot", "series_plot"]


def _save(fig: Any, path: str | Path) -> Path:
    """Lay the figure out, write it as PNG (atomically) and close it."""
    fig.tight_layout()
    return save_png(fig, path)


def run_plot(result: AthleticsResult, path: str | Path) -> Path:
    """COM height and vertical ground force (body weights) over time, the state changes
    marked, for an :class:`~reactmocap.athletics.behaviours.AthleticsResult`."""
    plt = pyplot()
    log = result.log
    t = log["t"]
    weight = result.report["mass_kg"] * 9.81
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 5), dpi=100, sharex=True)
    a1.plot(t, log["com"][:, 2], "k-", lw=1.5)
    a1.set_ylabel("COM height (m)")
    # the tick-mean force from the momentum, as the report's peak_grf_bw (not a sampled contact)
    tf, force = ground_force(log, result.report["mass_kg"], np.array([0.0, 0.0, -9.81]))
    a2.plot(tf, force[:, 2] / weight, "b-", lw=1.0)
    a2.set_ylabel("vertical GRF (BW)")
    a2.set_xlabel("time (s)")
    for time, _src, dst in result.transitions:
        for ax in (a1, a2):
            ax.axvline(time, color="0.7", lw=0.8)
        a1.text(time, a1.get_ylim()[1], dst, rotation=90, va="top", fontsize=7)
    a1.set_title(f"{result.behaviour} ({result.body})")
    return _save(fig, path)


def commanded_plot(
    panels: Mapping[str, tuple[Sequence[float], Sequence[float]]],
    path: str | Path,
    *,
    quantity: str,
    thesis: Mapping[str, tuple[Sequence[float], Sequence[float]]] | None = None,
) -> Path:
    """One panel per body: achieved against commanded (ours: dots; the thesis's where given:
    crosses), and the diagonal of a perfect performance (dashed), as Figs. 4.1 and 4.4."""
    plt = pyplot()
    fig, axes = plt.subplots(len(panels), 1, figsize=(5, 4 * len(panels)), dpi=100)
    axes = np.atleast_1d(axes)
    for ax, (name, (cmd, got)) in zip(axes, panels.items()):
        hi = max(cmd, default=1.0) * 1.25
        ax.plot([0, hi], [0, hi], "k--", lw=1, label="perfect")
        shown = np.minimum(np.asarray(got, dtype=float), hi)
        ax.plot(cmd, shown, "o-", color="C0", label="ours")
        for c, g in zip(cmd, got):
            if g > hi:  # off the chart: drawn at its top edge, labelled with its value
                ax.annotate(f"{g:.2f}", (c, hi), textcoords="offset points", xytext=(4, -10),
                            fontsize=7)  # fmt: skip
        if thesis and name in thesis:
            ax.plot(*thesis[name], "x", color="C3", label="thesis")
        ax.set_xlim(0, hi)
        ax.set_ylim(0, hi)
        ax.set_title(name)
        ax.set_xlabel(f"desired {quantity} (m)")
        ax.set_ylabel(f"actual {quantity} (m)")
        ax.legend(fontsize=8)
    return _save(fig, path)


def series_plot(
    curves: Mapping[str, tuple[Sequence[float], Sequence[float]]],
    path: str | Path,
    *,
    xlabel: str,
    ylabel: str,
    title: str = "",
    hline: float | None = None,
) -> Path:
    """Labelled curves (ground forces over time, and the like)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4), dpi=100)
    for label, (x, y) in curves.items():
        ax.plot(x, y, label=label, lw=1.2)
    if hline is not None:
        ax.axhline(hline, color="k", ls="--", lw=0.8)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8)
    return _save(fig, path)

"""Regression of a results folder against a stored baseline.

A baseline (JSON) holds per-metric statistics (median, p95, mean, count), the failure count, the
per-scenario values (by id) and the reactmocap/MuJoCo versions that made it. Each metric has a
tolerance ``max(abs, rel * |baseline|)`` and a direction (lower is better for every quality
metric; ``both`` when any change is suspicious). Defaults are in :data:`DEFAULT_TOLERANCES`; a
baseline file's ``"tolerances"`` table overrides them per metric.

Aggregates decide the verdict: a metric whose median or p95 (rate, for booleans) got worse beyond
its tolerance, or more failures, is a regression. Per-scenario changes (matched clip, values
beyond tolerance) are always reported and also fail in ``strict`` mode, which a golden test uses
so that any drift, better or worse, needs a deliberate ``--update``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Literal

from reactmocap.batch.results import QUALITY_METRICS, ResultStore, summarize
from reactmocap.batch.runners import versions
from reactmocap.errors import ConfigError
from reactmocap.io import atomic_write_text

__all__ = [
    "DEFAULT_TOLERANCES",
    "Comparison",
    "Line",
    "Tolerance",
    "compare",
    "format_comparison",
    "load_baseline",
    "load_results",
    "make_baseline",
    "regress",
]

BASELINE_FORMAT = 1
Direction = Literal["lower", "higher", "both"]
Verdict = Literal["ok", "better", "worse", "changed", "missing"]
#: boolean metrics are compared by their rate (mean of 0/1) instead of median and p95
BOOLEAN_METRICS = ("fell", "intended_fall")


@dataclass(frozen=True)
class Tolerance:
    abs: float = 0.0
    rel: float = 0.0
    direction: Direction = "lower"

    def allowed(self, base: float) -> float:
        return max(self.abs, self.rel * abs(base))

    def verdict(self, base: float | None, cur: float | None) -> Verdict:
        if base is None or cur is None:
            return "ok" if base is cur else "missing"
        d = cur - base
        if abs(d) <= self.allowed(base) * (1 + 1e-9) or (math.isnan(base) and math.isnan(cur)):
            return "ok"
        if self.direction == "both":
            return "changed"
        return "better" if (d < 0) == (self.direction == "lower") else "worse"


# Loose enough for the small differences between MuJoCo versions and platforms, tight enough to
# catch a real change in a quality distribution.
DEFAULT_TOLERANCES: dict[str, Tolerance] = {
    "match_distance": Tolerance(0.01, 0.05),
    "blend_root_offset_max_m": Tolerance(0.005, 0.10),
    "blend_joint_correction_max_rad": Tolerance(0.02, 0.10),
    "blend_root_turn_max_rad": Tolerance(0.02, 0.10),
    "stitch_velocity_jump_rad_s": Tolerance(0.25, 0.10),
    "foot_skate_m": Tolerance(0.01, 0.10),
    "penetration_max_m": Tolerance(0.005, 0.10),
    # the reaction itself: a smaller reaction is not better, a change is a change
    "reaction_displacement_m": Tolerance(0.01, 0.10, "both"),
    "reaction_direction_error_deg": Tolerance(2.0, 0.10),
    "transition_s": Tolerance(0.02, 0.10, "both"),
    "contact_impulse_Ns": Tolerance(1.0, 0.10, "both"),
    "character_overlap_max_m": Tolerance(0.003, 0.10),
    "attacker_speed_ratio": Tolerance(0.05, 0.05),
    "attacker_foot_skate_m": Tolerance(0.01, 0.10),
    "attacker_lift_m": Tolerance(0.01, 0.10),
    "warnings": Tolerance(0.0, 0.0),  # count per scenario
    "fell": Tolerance(0.05, 0.0),  # rate
    "intended_fall": Tolerance(0.05, 0.0, "both"),  # rate; neither direction is better
    "failures": Tolerance(0.0, 0.0),  # count
}


def _tolerances(overrides: Mapping[str, Any] | None, where: str) -> dict[str, Tolerance]:
    tols = dict(DEFAULT_TOLERANCES)
    for name, spec in (overrides or {}).items():
        if name not in tols:
            raise ConfigError(
                f"{where}: tolerances.{name}: unknown metric; valid are {sorted(tols)}"
            )
        if not isinstance(spec, dict) or set(spec) - {"abs", "rel", "direction"}:
            raise ConfigError(f"{where}: tolerances.{name}: expected {{abs, rel, direction}}")
        t = Tolerance(**{**asdict(tols[name]), **spec})
        nums = (t.abs, t.rel)
        if t.direction not in ("lower", "higher", "both") or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and v >= 0 for v in nums
        ):
            raise ConfigError(
                f"{where}: tolerances.{name}: abs, rel >= 0 and direction one of lower/higher/both"
            )
        tols[name] = t
    return tols


def load_results(results_dir: str | Path) -> tuple[list[dict[str, Any]], dict[str, str]]:
    """Rows of a results folder and the versions that produced them."""
    d = Path(results_dir)
    rows = list(ResultStore(d).load().values())
    if not rows:
        raise ConfigError(
            f"{d}: no results (results.jsonl missing or empty); run `reactmocap "
            "batch SWEEP.toml --out DIR` first"
        )
    try:
        vers = json.loads((d / "sweep.json").read_text()).get("versions") or versions()
    except (OSError, ValueError):
        vers = versions()
    return rows, vers


def _stats_of(rows: Sequence[Mapping[str, Any]]) -> dict[str, dict[str, float]]:
    return {k: v.to_dict() for k, v in summarize(rows, QUALITY_METRICS).metrics.items()}


def make_baseline(
    rows: Sequence[Mapping[str, Any]],
    vers: Mapping[str, str],
    tolerances: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """A baseline document from result rows; ``tolerances`` (overrides) are kept as given."""
    scen = {}
    for r in sorted(rows, key=lambda r: str(r["id"])):
        s: dict[str, Any] = {"status": r.get("status")}
        if r.get("status") == "ok":
            s.update(matched_clip=r.get("matched_clip"), matched_frame=r.get("matched_frame"))
            s.update({m: r.get(m) for m in QUALITY_METRICS})
        scen[str(r["id"])] = s
    tols = (
        tolerances
        if tolerances is not None
        else {k: asdict(v) for k, v in DEFAULT_TOLERANCES.items()}
    )
    return {
        "format": BASELINE_FORMAT,
        "versions": dict(vers),
        "count": len(rows),
        "failures": sum(r.get("status") != "ok" for r in rows),
        "stats": _stats_of(rows),
        "tolerances": dict(tols),
        "scenarios": scen,
    }


def load_baseline(path: str | Path) -> dict[str, Any]:
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except OSError as exc:
        raise ConfigError(
            f"{p}: cannot read baseline: {exc.strerror or exc}; create one with --update"
        ) from None
    except ValueError as exc:
        raise ConfigError(f"{p}: invalid JSON: {exc}") from None
    if not isinstance(doc, dict) or doc.get("format") != BASELINE_FORMAT or "stats" not in doc:
        raise ConfigError(f"{p}: not a reactmocap baseline (format {BASELINE_FORMAT})")
    _tolerances(doc.get("tolerances"), str(p))  # validate early
    _check_fields(doc, p)
    return doc


def _check_fields(doc: Mapping[str, Any], p: Path) -> None:
    """A ConfigError naming the field of a hand-edited baseline whose type :func:`compare`
    cannot use (it failed there with a traceback)."""

    def is_num(v: Any) -> bool:
        return isinstance(v, int | float) and not isinstance(v, bool)

    def table(key: str, rows: Callable[[Any], bool], expected: str) -> None:
        value = doc.get(key, {})
        if not isinstance(value, Mapping):
            raise ConfigError(f"{p}: {key}: expected a table, got {value!r}")
        for name, row in value.items():
            if not rows(row):
                raise ConfigError(f"{p}: {key}.{name}: expected {expected}, got {row!r}")

    for key in ("count", "failures"):
        if key in doc and not is_num(doc[key]):
            raise ConfigError(f"{p}: {key}: expected a number, got {doc[key]!r}")
    table("stats", lambda r: isinstance(r, Mapping) and all(
        v is None or is_num(v) for v in r.values()), "a table of numbers")  # fmt: skip
    table("scenarios", lambda r: isinstance(r, Mapping), "a table")
    table("versions", lambda r: r is None or isinstance(r, str), "a version string")


@dataclass(frozen=True)
class Line:
    metric: str
    stat: str
    baseline: float | None
    current: float | None
    tolerance: float
    verdict: Verdict

    @property
    def delta(self) -> float | None:
        if self.baseline is None or self.current is None:
            return None
        return self.current - self.baseline


@dataclass
class Comparison:
    lines: list[Line]
    notes: list[str] = field(default_factory=list)
    shared: int = 0  # scenario ids in both
    clip_changed: list[str] = field(default_factory=list)
    newly_failing: list[str] = field(default_factory=list)
    missing_ids: list[str] = field(default_factory=list)
    #: metric -> (ids worse, ids better or changed) beyond tolerance, per scenario
    per_scenario: dict[str, tuple[list[str], list[str]]] = field(default_factory=dict)
    strict: bool = False

    @property
    def aggregate_regressed(self) -> bool:
        bad = {"worse", "changed", "missing"} | ({"better"} if self.strict else set())
        return any(ln.verdict in bad for ln in self.lines)

    @property
    def scenario_drift(self) -> bool:
        return bool(
            self.clip_changed
            or self.newly_failing
            or self.missing_ids
            or any(w or b for w, b in self.per_scenario.values())
        )

    @property
    def regressed(self) -> bool:
        return self.aggregate_regressed or (self.strict and self.scenario_drift)


def compare(
    rows: Sequence[Mapping[str, Any]],
    baseline: Mapping[str, Any],
    vers: Mapping[str, str] | None = None,
    *,
    strict: bool = False,
) -> Comparison:
    tols = _tolerances(baseline.get("tolerances"), "baseline")
    cur_stats = _stats_of(rows)
    lines = []
    for metric in QUALITY_METRICS:
        base_m = baseline["stats"].get(metric)
        cur_m = cur_stats.get(metric)
        if base_m is None and cur_m is None:
            continue
        tol = tols[metric]
        for stat in ("mean",) if metric in BOOLEAN_METRICS else ("median", "p95"):
            b = None if base_m is None else base_m.get(stat)
            c = None if cur_m is None else cur_m.get(stat)
            lines.append(Line(metric, stat, b, c, tol.allowed(b or 0.0), tol.verdict(b, c)))
    fails = float(sum(r.get("status") != "ok" for r in rows))
    bf = float(baseline.get("failures", 0))
    lines.append(
        Line(
            "failures",
            "count",
            bf,
            fails,
            tols["failures"].allowed(bf),
            tols["failures"].verdict(bf, fails),
        )
    )
    cmp = Comparison(lines, strict=strict)

    bv = baseline.get("versions", {})
    cv = dict(vers) if vers is not None else versions()
    diff = [
        f"{k} {bv.get(k)} (baseline) vs {cv.get(k)} (now)"
        for k in ("reactmocap", "mujoco")
        if bv.get(k) != cv.get(k)
    ]
    if diff:
        cmp.notes.append(
            "VERSIONS DIFFER: " + "; ".join(diff) + ". Small simulation differences across "
            "MuJoCo versions are expected; if the changes below are accepted, refresh the "
            "baseline with --update."
        )
    if int(baseline.get("count", 0)) != len(rows):
        cmp.notes.append(
            f"scenario count differs: {baseline.get('count')} in the baseline, {len(rows)} now"
        )

    base_sc: Mapping[str, Mapping[str, Any]] = baseline.get("scenarios", {})
    by_id = {str(r["id"]): r for r in rows}
    cmp.missing_ids = sorted(set(base_sc) - set(by_id))
    for metric in QUALITY_METRICS:
        cmp.per_scenario[metric] = ([], [])
    for pid, b in base_sc.items():
        r = by_id.get(pid)
        if r is None:
            continue
        cmp.shared += 1
        if b.get("status") == "ok" and r.get("status") != "ok":
            cmp.newly_failing.append(pid)
        if b.get("status") != "ok" or r.get("status") != "ok":
            continue
        if (b.get("matched_clip"), b.get("matched_frame")) != (
            r.get("matched_clip"),
            r.get("matched_frame"),
        ):
            cmp.clip_changed.append(pid)
        for metric in QUALITY_METRICS:
            v = tols[metric].verdict(_num(b.get(metric)), _num(r.get(metric)))
            if v in ("worse", "missing"):
                cmp.per_scenario[metric][0].append(pid)
            elif v != "ok":
                cmp.per_scenario[metric][1].append(pid)
    return cmp


def _num(v: Any) -> float | None:
    return float(v) if isinstance(v, bool | int | float) else None


def _f(v: float | None, signed: bool = False) -> str:
    if v is None:
        return "-"
    return f"{v:+.4g}" if signed else f"{v:.4g}"


def format_comparison(c: Comparison) -> str:
    out = [*c.notes] + [""] * bool(c.notes)
    out.append(
        f"{'metric':32s} {'stat':6s} {'baseline':>10s} {'current':>10s} {'delta':>10s} "
        f"{'tolerance':>10s}  verdict"
    )
    for ln in c.lines:
        out.append(
            f"{ln.metric:32s} {ln.stat:6s} {_f(ln.baseline):>10s} {_f(ln.current):>10s} "
            f"{_f(ln.delta, True):>10s} {'±' + _f(ln.tolerance):>10s}  {ln.verdict}"
        )
    out.append("")
    out.append(
        f"per scenario ({c.shared} ids in both): matched clip/frame changed in "
        f"{len(c.clip_changed)}, newly failing {len(c.newly_failing)}, missing now "
        f"{len(c.missing_ids)}"
    )
    for metric, (worse, other) in c.per_scenario.items():
        if worse or other:
            out.append(
                f"  {metric}: beyond tolerance in {len(worse) + len(other)} "
                f"({len(worse)} worse) e.g. {(worse + other)[:3]}"
            )
    if c.regressed:
        why = "aggregate metrics got worse" if c.aggregate_regressed else "scenarios drifted"
        out.append(f"REGRESSION ({why}{', strict mode' if c.strict else ''})")
    else:
        out.append("no regression")
    return "\n".join(out)


def regress(
    results_dir: str | Path,
    baseline_path: str | Path,
    *,
    update: bool = False,
    strict: bool = False,
) -> tuple[int, str]:
    """Compare (or with ``update``, rewrite) a baseline; returns (exit code, report text)."""
    rows, vers = load_results(results_dir)
    bp = Path(baseline_path)
    if update:
        old_tols = load_baseline(bp).get("tolerances") if bp.exists() else None
        doc = make_baseline(rows, vers, old_tols)
        atomic_write_text(bp, json.dumps(doc, indent=1, sort_keys=False) + "\n")
        return 0, (
            f"wrote baseline {bp}: {doc['count']} scenarios, {doc['failures']} failed, "
            f"versions {doc['versions']}"
        )
    cmp = compare(rows, load_baseline(bp), vers, strict=strict)
    return (1 if cmp.regressed else 0), format_comparison(cmp)

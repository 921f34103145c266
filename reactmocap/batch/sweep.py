"""Sweep files (TOML): a base scenario plus axes to vary, expanded into a grid of scenarios.

```toml
[sweep]                      # optional
name = "facing"
subsample = 12               # keep 12 grid points (or a fraction such as 0.25) ...
seed = 0                     # ... chosen deterministically from this seed

[base]                       # a scenario, same schema as a scenario file
library = "../data/synthetic_clips"
[base.recipient]
clip = "guard"
[base.attacker]
clip = "front_kick"
# or instead of [base]: base = "front_kick.toml"

[axes]
facing_deg = { start = 0, stop = 350, step = 10 }   # stop is inclusive
attacker_clip = ["front_kick", "side_kick"]
```

Each axis value is applied to the raw base mapping and the result is validated with
:func:`~reactmocap.response.scenario.parse_scenario`, so a sweep point is checked exactly like a
scenario file. Every point gets a stable id (``sha1`` of its canonical parameters, 12 hex) so
results join across runs and a rerun can skip what is done.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import random
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Literal

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.response.scenario import ImpactSpec, ResponseConfig, Scenario, parse_scenario

__all__ = ["AXES", "Axis", "Sweep", "SweepPoint", "load_sweep", "parse_sweep", "point_id"]

Value = float | int | str
#: guard against typos such as step = 0.0001 expanding into millions of scenarios
MAX_AXIS_VALUES = 100_000


@dataclass(frozen=True)
class Axis:
    """One kind of variation: how its values are typed and how one is applied to the raw
    scenario mapping (before validation)."""

    name: str
    kind: Literal["float", "int", "str"]
    help: str
    apply: Callable[[dict[str, Any], Any], None]
    unit: str = ""


def _section(raw: dict[str, Any], key: str, axis: str) -> dict[str, Any]:
    sec = raw.get(key)
    if not isinstance(sec, dict):
        raise ConfigError(f"[axes].{axis}: the base scenario has no [{key}] table to vary")
    return sec


def _base_force(raw: dict[str, Any], axis: str) -> list[float]:
    imp = _section(raw, "impact", axis)
    force = imp.get("force", list(ImpactSpec.force))
    if not (isinstance(force, list) and len(force) == 3):
        return force  # type: ignore[no-any-return]  # parse_scenario reports the bad field
    return [float(f) for f in force]


def _set_force_magnitude(raw: dict[str, Any], v: float) -> None:
    f = _base_force(raw, "force_N")
    norm = math.sqrt(sum(c * c for c in f))
    if norm == 0:
        raise ConfigError("[axes].force_N: the base [impact].force is zero, so it has no direction")
    raw["impact"]["force"] = [c * v / norm for c in f]


def _set_force_direction(raw: dict[str, Any], v: float) -> None:
    # keeps the horizontal magnitude and the vertical component; only the heading turns
    f = _base_force(raw, "force_dir_deg")
    h = math.hypot(f[0], f[1])
    if h == 0:
        raise ConfigError("[axes].force_dir_deg: the base [impact].force has no horizontal part")
    a = math.radians(v)
    raw["impact"]["force"] = [h * math.cos(a), h * math.sin(a), f[2]]


def _setter(section: str, key: str) -> Callable[[dict[str, Any], Any], None]:
    def apply(raw: dict[str, Any], v: Any) -> None:
        if section == "response":
            raw.setdefault("response", {})
        _section(raw, section, key)[key] = v

    return apply


def _set_seed(raw: dict[str, Any], v: int) -> None:
    # The pipeline is deterministic; a seed is a replicate label unless the response config
    # grows a ``seed`` field, which then receives it.
    if "seed" in {f.name for f in fields(ResponseConfig)}:
        raw.setdefault("response", {})["seed"] = v


AXES: dict[str, Axis] = {
    a.name: a
    for a in (
        Axis(
            "facing_deg",
            "float",
            "recipient facing (deg)",
            _setter("recipient", "facing_deg"),
            "deg",
        ),
        Axis(
            "force_N",
            "float",
            "impact force magnitude (N); needs [impact]",
            _set_force_magnitude,
            "N",
        ),
        Axis(
            "force_dir_deg",
            "float",
            "horizontal heading of the impact force (deg)",
            _set_force_direction,
            "deg",
        ),
        Axis(
            "impact_body", "str", "body part hit by the explicit impact", _setter("impact", "body")
        ),
        Axis("attacker_clip", "str", "the attacker's clip", _setter("attacker", "clip")),
        Axis(
            "recipient_start",
            "float",
            "seconds into the recipient's clip at the start",
            _setter("recipient", "start"),
            "s",
        ),
        Axis(
            "reaction_delay",
            "float",
            "[response].reaction_delay (s)",
            _setter("response", "reaction_delay"),
            "s",
        ),
        Axis("seed", "int", "replicate seed", _set_seed),
    )
}


def point_id(params: Mapping[str, Value]) -> str:
    """Stable 12-hex id of a parameter set (canonical JSON, sorted keys, floats as floats)."""
    canon = json.dumps(dict(params), sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha1(canon.encode()).hexdigest()[:12]


@dataclass(frozen=True)
class SweepPoint:
    """One expanded scenario: its grid ``index``, stable ``id`` and swept ``params``."""

    id: str
    index: int
    params: dict[str, Value]
    scenario: Scenario


@dataclass(frozen=True)
class Sweep:
    name: str
    base: dict[str, Any]  # raw scenario mapping, as in a scenario file
    base_dir: Path  # where the base's relative paths resolve first
    axes: dict[str, tuple[Value, ...]]
    subsample: int | float | None = None  # an int count, or a float fraction in (0, 1]
    seed: int = 0
    source: str = "<sweep>"
    _grid_size: int = field(init=False, repr=False, default=0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_grid_size", math.prod(len(v) for v in self.axes.values()))

    @property
    def grid_size(self) -> int:
        return self._grid_size

    def fingerprint(self) -> str:
        """Hash of the base scenario: results in a folder only join with the same base."""
        canon = json.dumps(self.base, sort_keys=True, default=str)
        return hashlib.sha1(canon.encode()).hexdigest()[:12]

    def selected(self) -> list[int]:
        """Grid indices kept after subsampling, in grid order."""
        n = self.grid_size
        if self.subsample is None:
            return list(range(n))
        if isinstance(self.subsample, int):
            k = self.subsample
        else:
            k = max(1, round(self.subsample * n))
        if k >= n:
            return list(range(n))
        return sorted(random.Random(self.seed).sample(range(n), k))

    def points(self) -> list[SweepPoint]:
        """Expand and validate every selected grid point."""
        names = list(self.axes)
        grid = list(itertools.product(*self.axes.values()))
        out = []
        for i in self.selected():
            params = dict(zip(names, grid[i]))
            out.append(SweepPoint(point_id(params), i, params, self.scenario(params)))
        return out

    def scenario(self, params: Mapping[str, Value]) -> Scenario:
        raw = copy.deepcopy(self.base)
        try:
            for name, value in params.items():
                AXES[name].apply(raw, value)
            sc = parse_scenario(raw, source=f"{self.source} [base]", base_dir=self.base_dir)
        except ConfigError as exc:
            raise ConfigError(f"{self.source}: sweep point {dict(params)}: {exc}") from None
        return sc.with_changes(name=f"{self.name}-{point_id(params)}")


_TOP = {"base", "axes", "sweep"}
_SWEEP_KEYS = {"name", "subsample", "seed"}


def _fail(source: str, where: str, msg: str) -> ConfigError:
    return ConfigError(f"{source}: {where}: {msg}")


def _typed(source: str, axis: Axis, i: int, v: Any) -> Value:
    where = f"[axes].{axis.name}[{i}]"
    if axis.kind == "str":
        if not isinstance(v, str) or not v:
            raise _fail(source, where, f"expected a non-empty string, got {v!r}")
        return v
    if isinstance(v, bool) or not isinstance(v, int | float):
        unit = f" ({axis.unit})" if axis.unit else ""
        raise _fail(source, where, f"expected a number{unit}, got {v!r}")
    if axis.kind == "int":
        if not isinstance(v, int):
            raise _fail(source, where, f"expected an integer, got {v!r}")
        return v
    if not math.isfinite(v):
        raise _fail(source, where, f"expected a finite number, got {v!r}")
    return float(v) + 0.0  # + 0.0 turns -0.0 into 0.0 so ids do not split on the sign of zero


def _axis_values(source: str, axis: Axis, spec: Any) -> tuple[Value, ...]:
    where = f"[axes].{axis.name}"
    if isinstance(spec, dict):
        if axis.kind == "str":
            raise _fail(source, where, "a {start, stop, step} range needs a numeric axis")
        unknown = sorted(set(spec) - {"start", "stop", "step"})
        missing = sorted({"start", "stop", "step"} - set(spec))
        if unknown or missing:
            raise _fail(
                source,
                where,
                f"a range is {{start, stop, step}}; unknown {unknown}, missing {missing}",
            )
        start, stop, step = (_typed(source, axis, 0, spec[k]) for k in ("start", "stop", "step"))
        assert isinstance(start, int | float) and isinstance(stop, int | float)
        assert isinstance(step, int | float)
        if step <= 0:
            raise _fail(source, where, f"step must be > 0, got {step}")
        count = math.floor((stop - start) / step + 1e-9) + 1
        if count > MAX_AXIS_VALUES:
            raise _fail(source, where, f"{count} values (more than {MAX_AXIS_VALUES})")
        values: list[Any] = [start + k * step for k in range(max(count, 0))]
        if axis.kind == "float":
            values = [round(float(v), 9) + 0.0 for v in values]
    elif isinstance(spec, list):
        values = [_typed(source, axis, i, v) for i, v in enumerate(spec)]
    else:
        values = [_typed(source, axis, 0, spec)]  # a single value
    if not values:
        raise _fail(source, where, "is empty; give at least one value")
    dupes = sorted({str(v) for v in values if values.count(v) > 1})
    if dupes:
        raise _fail(source, where, f"repeats value(s) {dupes}")
    return tuple(values)


def parse_sweep(
    data: Mapping[str, Any], *, source: str = "<sweep>", base_dir: Path | None = None
) -> Sweep:
    """Validate a sweep mapping (as read from TOML); raises ConfigError naming the field."""
    base_dir = base_dir if base_dir is not None else Path.cwd()
    unknown = sorted(set(data) - _TOP)
    if unknown:
        hint = (
            (
                "; this looks like a scenario file: put it under [base] or write "
                'base = "scenario.toml"'
            )
            if {"recipient", "library"} & set(unknown)
            else ""
        )
        raise _fail(
            source, "top level", f"unknown key(s) {unknown}; valid keys are {sorted(_TOP)}{hint}"
        )
    meta = data.get("sweep", {})
    if not isinstance(meta, dict):
        raise _fail(source, "[sweep]", "expected a table")
    bad = sorted(set(meta) - _SWEEP_KEYS)
    if bad:
        raise _fail(
            source, "[sweep]", f"unknown key(s) {bad}; valid keys are {sorted(_SWEEP_KEYS)}"
        )
    name = meta.get("name", Path(source).stem)
    if not isinstance(name, str) or not name:
        raise _fail(source, "[sweep].name", f"expected a non-empty string, got {name!r}")
    sub = meta.get("subsample")
    if sub is not None and (
        isinstance(sub, bool)
        or not isinstance(sub, int | float)
        or sub <= 0
        or (isinstance(sub, float) and sub > 1 and not sub.is_integer())
    ):
        raise _fail(
            source,
            "[sweep].subsample",
            f"expected a count >= 1 or a fraction in (0, 1], got {sub!r}",
        )
    seed = meta.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise _fail(source, "[sweep].seed", f"expected an integer, got {seed!r}")

    if "base" not in data:
        raise _fail(source, "base", 'missing: a [base] scenario table or base = "scenario.toml"')
    base, scen_dir = _base(source, data["base"], base_dir)

    axes_raw = data.get("axes", {})
    if not isinstance(axes_raw, dict):
        raise _fail(source, "[axes]", "expected a table")
    axes: dict[str, tuple[Value, ...]] = {}
    for key, spec in axes_raw.items():
        if key not in AXES:
            raise UnknownKeyError(
                f"{source}: [axes]: unknown axis {key!r}; valid axes are {sorted(AXES)}"
            )
        axes[key] = _axis_values(source, AXES[key], spec)
    if "force_N" in axes or "force_dir_deg" in axes or "impact_body" in axes:
        if "impact" not in base:
            raise _fail(
                source,
                "[axes]",
                "force_N, force_dir_deg and impact_body need an explicit [base.impact]",
            )
    if "attacker_clip" in axes and "attacker" not in base:
        raise _fail(source, "[axes].attacker_clip", "the base scenario has no [attacker]")
    if isinstance(sub, float) and sub > 1:
        sub = int(sub)  # 12.0 means a count, like 12
    sweep = Sweep(name, base, scen_dir, axes, sub, seed, source)
    parse_scenario(base, source=f"{source} [base]", base_dir=scen_dir)  # base errors first
    return sweep


def _base(source: str, spec: Any, base_dir: Path) -> tuple[dict[str, Any], Path]:
    if isinstance(spec, dict):
        return copy.deepcopy(spec), base_dir
    if not isinstance(spec, str) or not spec:
        raise _fail(source, "base", f"expected a table or a scenario file path, got {spec!r}")
    p = Path(spec)
    cands = [p] if p.is_absolute() else [base_dir / p, Path.cwd() / p]
    for c in cands:
        if c.is_file():
            try:
                return tomllib.loads(c.read_text()), c.parent
            except (OSError, tomllib.TOMLDecodeError) as exc:
                raise _fail(source, "base", f"cannot read {c}: {exc}") from None
    raise _fail(source, "base", f"{spec!r} not found (looked in {[str(c) for c in cands]})")


def load_sweep(path: str | Path) -> Sweep:
    """Read and validate a sweep TOML file."""
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text())
    except OSError as exc:
        raise ConfigError(f"{p}: cannot read sweep file: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{p}: invalid TOML: {exc}") from None
    return parse_sweep(data, source=str(p), base_dir=p.parent)

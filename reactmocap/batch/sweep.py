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
"recipient.facing_deg" = { start = 0, stop = 350, step = 10 }   # stop is inclusive
"attacker.clip" = ["front_kick", "side_kick"]
"response.kp" = [2000, 4000]
"attacker.position" = [[0.9, 0.0], [1.1, 0.2]]   # a vector field takes a list of lists
```

Every field of a scenario table is an axis named ``table.key`` (derived from the dataclasses of
:mod:`reactmocap.response.scenario`, so a new field is sweepable without touching this file),
typed by its annotation; ``force_N``, ``force_dir_deg`` and ``seed`` are derived axes, and the
short names of earlier versions (``facing_deg``, ...) stay as aliases (:data:`ALIASES`). Each
value is applied to the raw base mapping and the result is validated with
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
import types
import typing
from collections.abc import Callable, Mapping
from dataclasses import MISSING, dataclass, field, fields
from pathlib import Path
from typing import Any, Literal

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.io import read_toml
from reactmocap.response.scenario import (
    AttackerSpec,
    CharacterSpec,
    ImpactSpec,
    ResponseConfig,
    Scenario,
    parse_scenario,
)

__all__ = [
    "ALIASES",
    "AXES",
    "TABLES",
    "Axis",
    "Sweep",
    "SweepPoint",
    "describe_axes",
    "load_sweep",
    "parse_sweep",
    "point_id",
]

#: a swept value: numbers, names and flags, or a list of numbers for a vector field
Value = float | int | str | bool | list[Any]
Kind = Literal["float", "int", "str", "bool", "vector", "value"]
#: guard against typos such as step = 0.0001 expanding into millions of scenarios
MAX_AXIS_VALUES = 100_000

#: the scenario tables whose every field is an axis ``table.key``
TABLES: dict[str, type] = {
    "recipient": CharacterSpec,
    "attacker": AttackerSpec,
    "impact": ImpactSpec,
    "response": ResponseConfig,
}
#: the axis names of earlier versions. They are also the parameter keys (results columns, point
#: ids) of their fields whichever name a sweep file uses, so existing results folders and
#: baselines keep joining.
ALIASES: dict[str, str] = {
    "facing_deg": "recipient.facing_deg",
    "impact_body": "impact.body",
    "attacker_clip": "attacker.clip",
    "recipient_start": "recipient.start",
    "reaction_delay": "response.reaction_delay",
}


@dataclass(frozen=True)
class Axis:
    """One kind of variation: how its values are typed and how one is applied to the raw
    scenario mapping (before validation)."""

    name: str  # "table.key" for a field, else the derived axis' name
    kind: Kind
    help: str
    apply: Callable[[dict[str, Any], Any], None]
    unit: str = ""
    #: parameter key of a point (its results column, part of its id): the alias if one exists
    key: str = ""
    #: scenario table the axis changes; "attacker" and "impact" must be in the base
    table: str | None = None
    #: items of a vector value (0: any number of items, or not a vector)
    length: int = 0
    #: applied after the field axes (derived from a field they may set too, e.g. the force)
    derived: bool = False

    def __post_init__(self) -> None:
        if not self.key:
            object.__setattr__(self, "key", self.name)


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
        if section == "response":  # optional table with defaults for every key
            raw.setdefault("response", {})
        _section(raw, section, key)[key] = copy.deepcopy(v)  # lists stay the point's own

    return apply


def _set_seed(raw: dict[str, Any], v: int) -> None:
    """A replicate label: only the point id changes (the pipeline is deterministic)."""


def _kind(hint: Any) -> tuple[Kind, int]:
    """The axis kind (and vector length) of a field annotation; "value" for anything else,
    which is passed through for parse_scenario to judge."""
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):  # X | None: a TOML value is never None
        members = [a for a in typing.get_args(hint) if a is not type(None)]
        if len(members) == 1:
            return _kind(members[0])
    if origin is Literal:  # e.g. sim1_mode; parse_scenario checks the allowed values
        kinds = {_kind(type(a))[0] for a in typing.get_args(hint)}
        return (kinds.pop(), 0) if len(kinds) == 1 else ("value", 0)
    if origin is tuple:
        items = typing.get_args(hint)
        if len(items) == 2 and items[1] is Ellipsis and items[0] in (float, int):
            return "vector", 0
        if items and all(a in (float, int) for a in items):
            return "vector", len(items)
    simple: dict[Any, Kind] = {bool: "bool", int: "int", float: "float", str: "str"}
    return simple.get(hint, "value"), 0


def _field_axes(table: str, cls: type) -> list[Axis]:
    """One axis per dataclass field of a scenario table, typed by its annotation."""
    hints = typing.get_type_hints(cls)
    key_of = {full: short for short, full in ALIASES.items()}
    out = []
    for f in fields(cls):
        name = f"{table}.{f.name}"
        kind, length = _kind(hints[f.name])
        if f.default is not MISSING:
            default = f"default {list(f.default) if isinstance(f.default, tuple) else f.default!r}"
        elif f.default_factory is not MISSING:
            default = "default from a factory"
        else:
            default = "required"
        unit = "deg" if f.name.endswith("_deg") else ""
        what = f"{kind} ({unit})" if unit else kind
        if kind == "vector":
            what = f"vector: a list of {length or 'any number of'} numbers per value"
        out.append(
            Axis(
                name,
                kind,
                f"{what}, {default}",
                _setter(table, f.name),
                unit,
                key_of.get(name, name),
                table,
                length,
            )
        )
    return out


_DERIVED = (
    Axis(
        "force_N",
        "float",
        "impact force magnitude (N), keeping the base [impact].force's direction",
        _set_force_magnitude,
        "N",
        table="impact",
        derived=True,
    ),
    Axis(
        "force_dir_deg",
        "float",
        "horizontal heading of the base [impact].force (deg), keeping its horizontal "
        "magnitude and vertical part",
        _set_force_direction,
        "deg",
        table="impact",
        derived=True,
    ),
    Axis(
        "seed",
        "int",
        "replicate label: changes the point id (so a scenario can be run several times) and "
        "nothing in the scenario",
        _set_seed,
        derived=True,
    ),
)


def _all_axes() -> dict[str, Axis]:
    axes = {a.name: a for table, cls in TABLES.items() for a in _field_axes(table, cls)}
    axes.update((a.name, a) for a in _DERIVED)
    for short, full in ALIASES.items():
        axes[short] = axes[full]  # an alias whose field went away fails at import, loudly
    return axes


#: every accepted axis name (``table.key`` fields, derived axes, aliases) -> its axis
AXES: dict[str, Axis] = _all_axes()


def _valid_axes() -> list[str]:
    fields_ = sorted(n for n, a in AXES.items() if n == a.name and not a.derived)
    return fields_ + [a.name for a in _DERIVED] + sorted(ALIASES)


def describe_axes() -> str:
    """The sweepable axes, one per line (for help texts and docs)."""
    alias_of = {full: short for short, full in ALIASES.items()}
    lines = []
    for name in _valid_axes():
        if name in ALIASES:
            continue
        a = AXES[name]
        also = f"; alias {alias_of[name]}" if name in alias_of else ""
        lines.append(f"  {name:<28} {a.help}{also}")
    return "\n".join(lines)


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
    """A base scenario and the values of each axis, keyed by parameter key (:attr:`Axis.key`:
    the alias where a field has one), which is what point ids and results columns use."""

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
            params = copy.deepcopy(dict(zip(names, grid[i])))  # vector values: own lists
            out.append(SweepPoint(point_id(params), i, params, self.scenario(params)))
        return out

    def scenario(self, params: Mapping[str, Value]) -> Scenario:
        raw = copy.deepcopy(self.base)
        # field axes first, so force_N / force_dir_deg act on a swept impact.force
        order = sorted(params.items(), key=lambda kv: _axis(self.source, kv[0]).derived)
        try:
            for name, value in order:
                AXES[name].apply(raw, value)
            sc = parse_scenario(raw, source=f"{self.source} [base]", base_dir=self.base_dir)
        except ConfigError as exc:
            raise ConfigError(f"{self.source}: sweep point {dict(params)}: {exc}") from None
        return sc.with_changes(name=f"{self.name}-{point_id(params)}")


_TOP = {"base", "axes", "sweep"}
_SWEEP_KEYS = {"name", "subsample", "seed"}


def _fail(source: str, where: str, msg: str) -> ConfigError:
    return ConfigError(f"{source}: {where}: {msg}")


def _axis(source: str, name: str) -> Axis:
    axis = AXES.get(name)
    if axis is None:
        raise UnknownKeyError(
            f"{source}: [axes]: unknown axis {name!r}; valid axes are {_valid_axes()}"
        )
    return axis


def _number(source: str, where: str, axis: Axis, v: Any) -> float | int:
    if isinstance(v, bool) or not isinstance(v, int | float):
        unit = f" ({axis.unit})" if axis.unit else ""
        raise _fail(source, where, f"expected a number{unit}, got {v!r}")
    if not math.isfinite(v):
        raise _fail(source, where, f"expected a finite number, got {v!r}")
    return v


def _plain(source: str, where: str, v: Any) -> Any:
    """A value of an axis of unknown type: anything JSON can hash into an id."""
    if isinstance(v, list):
        return [_plain(source, f"{where}[{i}]", x) for i, x in enumerate(v)]
    if isinstance(v, float) and not math.isfinite(v):
        raise _fail(source, where, f"expected a finite number, got {v!r}")
    if not isinstance(v, str | int | float):  # bool is an int; tables and dates are refused
        raise _fail(source, where, f"expected a string, number, boolean or list, got {v!r}")
    return v


def _typed(source: str, name: str, axis: Axis, i: int, v: Any) -> Value:
    """``v`` checked against the axis kind and made canonical (ids must not depend on 1 vs
    1.0); ranges and names are left to parse_scenario, as in a scenario file."""
    where = f"[axes].{name}[{i}]"
    if axis.kind == "str":
        if not isinstance(v, str) or not v:
            raise _fail(source, where, f"expected a non-empty string, got {v!r}")
        return v
    if axis.kind == "bool":
        if not isinstance(v, bool):
            raise _fail(source, where, f"expected true or false, got {v!r}")
        return v
    if axis.kind == "vector":
        n = axis.length
        if not isinstance(v, list) or (n and len(v) != n):
            raise _fail(source, where, f"expected a list of {n or 'some'} numbers, got {v!r}")
        return [float(_number(source, f"{where}[{k}]", axis, x)) + 0.0 for k, x in enumerate(v)]
    if axis.kind == "value":
        return _plain(source, where, v)  # type: ignore[no-any-return]
    num = _number(source, where, axis, v)
    if axis.kind == "int":
        if not isinstance(num, int):
            raise _fail(source, where, f"expected an integer, got {v!r}")
        return num
    return float(num) + 0.0  # + 0.0 turns -0.0 into 0.0 so ids do not split on the sign of zero


def _axis_values(source: str, name: str, axis: Axis, spec: Any) -> tuple[Value, ...]:
    where = f"[axes].{name}"
    if isinstance(spec, dict):
        if axis.kind not in ("float", "int"):
            raise _fail(source, where, "a {start, stop, step} range needs a numeric axis")
        unknown = sorted(set(spec) - {"start", "stop", "step"})
        missing = sorted({"start", "stop", "step"} - set(spec))
        if unknown or missing:
            raise _fail(
                source,
                where,
                f"a range is {{start, stop, step}}; unknown {unknown}, missing {missing}",
            )
        start, stop, step = (
            _typed(source, name, axis, 0, spec[k]) for k in ("start", "stop", "step")
        )
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
        values = [_typed(source, name, axis, i, v) for i, v in enumerate(spec)]
    else:
        values = [_typed(source, name, axis, 0, spec)]  # a single value
    if not values:
        raise _fail(source, where, "is empty; give at least one value")
    dupes = sorted({str(v) for v in values if values.count(v) > 1})
    if dupes:
        raise _fail(source, where, f"repeats value(s) {dupes}")
    return tuple(values)


def _flatten(axes_raw: Mapping[str, Any]) -> list[tuple[str, Any]]:
    """``[axes]`` entries as (name, spec). An unquoted dotted key (``response.kp = [...]``)
    reads as a nested TOML table; it means the same as the quoted ``"response.kp"``."""
    out: list[tuple[str, Any]] = []
    for key, spec in axes_raw.items():
        if key in TABLES and isinstance(spec, dict):
            out.extend((f"{key}.{k}", v) for k, v in spec.items())
        else:
            out.append((key, spec))
    return out


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
    used: dict[str, str] = {}  # parameter key -> the name the file gave it
    needs: dict[str, list[str]] = {}  # optional table -> axes that vary it
    for name, spec in _flatten(axes_raw):
        axis = _axis(source, name)
        if axis.key in used:
            raise _fail(
                source, f"[axes].{name}", f"varies the same field as [axes].{used[axis.key]}"
            )
        used[axis.key] = name
        # ids and columns use the parameter key, so both spellings of a field join
        axes[axis.key] = _axis_values(source, name, axis, spec)
        if axis.table in ("attacker", "impact") and axis.table not in base:
            needs.setdefault(axis.table, []).append(name)
    if needs:
        table, names = next(iter(needs.items()))
        raise _fail(
            source,
            "[axes]",
            f"{', '.join(names)} need{'s' * (len(names) == 1)} an explicit [base.{table}]",
        )
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
    data = read_toml(p, "sweep")
    return parse_sweep(data, source=str(p), base_dir=p.parent)

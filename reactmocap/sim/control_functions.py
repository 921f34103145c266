"""Deva's control functions: one cubic-spline curve per degree of freedom against time.

Seed ``003`` (Deva), section 3: "A control function is a curve of either position versus time
(for kinematic control) or force/torque versus time (for dynamic control). A unique control
function is associated with each degree of freedom ... Control functions are cubic interpolatory
spline curves which are defined by user-specified defining points."

* :class:`ControlFunction`: one interpolating cubic spline (``scipy.interpolate.CubicSpline``)
  through a few control points ``(t_i, v_i)``.
* :class:`ControlFunctionSet`: DOF name -> curve, all of one kind (``"angle"`` in radians or
  ``"torque"`` in N m), evaluated together at a time ``t`` into a caller's array.

Outside ``[t_0, t_last]`` a curve **holds** its end value: a controller that runs past a curve
keeps the last pose or torque instead of extrapolating a cubic. The derivative is the spline's on
``[t_0, t_last)`` and 0 before ``t_0`` and from ``t_last`` on (the held part), so it is
right-continuous. Use ``bc_type="clamped"`` for curves whose slope should vanish at the ends.
"""

from __future__ import annotations

import bisect
from collections.abc import Mapping
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from reactmocap.errors import ConfigError, UnknownKeyError

__all__ = ["BoundaryCondition", "ControlFunction", "ControlFunctionSet", "ControlKind"]

ControlKind = Literal["angle", "torque"]
#: scipy's end conditions: "not-a-knot" (default), "natural" (zero 2nd derivative), "clamped"
#: (zero slope: the curve eases in and out, so holding past the ends has no velocity jump)
BoundaryCondition = Literal["not-a-knot", "natural", "clamped"]
_KINDS = ("angle", "torque")
_BCS = ("not-a-knot", "natural", "clamped")


class ControlFunction:
    """Cubic interpolating spline through ``(times[i], values[i])``; ``dof`` names it in errors.

    Attributes ``times``, ``values`` (read-only float arrays), ``bc_type``, ``dof`` and ``spline``
    (the ``scipy.interpolate.CubicSpline``).

    Raises:
        ConfigError: fewer than 2 points, lengths differ, non-finite entries, times not strictly
            increasing, or an unknown ``bc_type`` (the message names the DOF and the field).
    """

    def __init__(
        self,
        times: ArrayLike,
        values: ArrayLike,
        bc_type: BoundaryCondition = "not-a-knot",
        dof: str = "control function",
    ) -> None:
        where = f"control function {dof!r}"
        t = _vector(times, where, "times")
        v = _vector(values, where, "values")
        if t.size < 2:
            raise ConfigError(f"{where}: times needs at least 2 control points, got {t.size}")
        if v.size != t.size:
            raise ConfigError(f"{where}: values has {v.size} entries but times has {t.size}")
        bad = np.flatnonzero(np.diff(t) <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            raise ConfigError(
                f"{where}: times must be strictly increasing (times[{i}] = {t[i]} <= "
                f"times[{i - 1}] = {t[i - 1]})"
            )
        if bc_type not in _BCS:
            raise ConfigError(f"{where}: bc_type must be one of {list(_BCS)}, got {bc_type!r}")
        t.setflags(write=False)
        v.setflags(write=False)
        self.times: NDArray[np.float64] = t
        self.values: NDArray[np.float64] = v
        self.bc_type: BoundaryCondition = bc_type
        self.dof = dof
        self.spline = CubicSpline(t, v, bc_type=bc_type)

    def __repr__(self) -> str:
        return f"ControlFunction(dof={self.dof!r}, points={self.times.size}, bc={self.bc_type!r})"

    @property
    def t_start(self) -> float:
        return float(self.times[0])

    @property
    def t_end(self) -> float:
        return float(self.times[-1])

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        """Value at ``t`` (scalar or array); exactly the end values outside the range."""
        t = np.asarray(t, dtype=np.float64)
        v = self.spline(np.clip(t, self.times[0], self.times[-1]))
        v = np.where(t <= self.times[0], self.values[0], v)
        return np.where(t >= self.times[-1], self.values[-1], v)

    def derivative(self, t: ArrayLike) -> NDArray[np.float64]:
        """d value / dt at ``t`` (desired velocity for an angle curve); 0 outside
        ``[t_start, t_end)``."""
        t = np.asarray(t, dtype=np.float64)
        inside = (t >= self.times[0]) & (t < self.times[-1])
        return np.where(inside, self.spline(np.clip(t, self.times[0], self.times[-1]), 1), 0.0)


def _vector(x: ArrayLike, where: str, name: str) -> NDArray[np.float64]:
    try:
        arr = np.array(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"{where}: {name} must be numbers, got {x!r}") from None
    if arr.ndim != 1:
        raise ConfigError(f"{where}: {name} must be a 1-D sequence, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = np.flatnonzero(~np.isfinite(arr)).tolist()
        raise ConfigError(f"{where}: {name} contains NaN or inf at {bad}")
    return arr


class ControlFunctionSet:
    """DOF name -> :class:`ControlFunction`, evaluated for all DOFs at once.

    The curves' pieces are repacked into per-time-region tables: the union of all control times
    cuts the time axis into regions, and within one region every curve is a single cubic. A call
    finds the region by bisection and evaluates all DOFs with one matrix-vector product into
    ``out``, so ``evaluate(t, out=buf)`` allocates no per-step arrays (about 3 us for 51 DOFs).
    It reuses a small scratch buffer: share a set between threads only for reading curves.
    """

    def __init__(
        self,
        curves: Mapping[str, ControlFunction | tuple[ArrayLike, ArrayLike]],
        kind: ControlKind = "angle",
    ) -> None:
        if kind not in _KINDS:
            raise ConfigError(
                f"control function set: kind must be one of {list(_KINDS)}, got {kind!r}"
            )
        if not curves:
            raise ConfigError("control function set: needs at least one DOF curve")
        funcs: list[ControlFunction] = []
        for name, curve in curves.items():
            if not isinstance(name, str) or not name:
                raise ConfigError(f"control function set: DOF names must be strings, got {name!r}")
            if isinstance(curve, ControlFunction):
                if curve.dof != name:
                    curve = ControlFunction(curve.times, curve.values, curve.bc_type, name)
                funcs.append(curve)
            else:
                try:
                    times, values = curve
                except (TypeError, ValueError):
                    raise ConfigError(
                        f"control function {name!r}: expected a ControlFunction or (times, values)"
                    ) from None
                funcs.append(ControlFunction(times, values, dof=name))
        self.kind: ControlKind = kind
        self.names: tuple[str, ...] = tuple(curves)
        self.functions: tuple[ControlFunction, ...] = tuple(funcs)
        self._build_tables()

    def _build_tables(self) -> None:
        funcs = self.functions
        knots = np.unique(np.concatenate([f.times for f in funcs]))
        # regions: 0 before all knots, k in [knots[k-1], knots[k]), the last from the last knot on
        origin = np.concatenate([knots[:1], knots])
        mids = np.concatenate([[knots[0] - 1.0], 0.5 * (knots[:-1] + knots[1:]), [knots[-1] + 1.0]])
        # (region, dof, 4): every curve's piece re-expanded about the region's origin u, so one
        # scalar tau = t - u serves all DOFs: p = a tau^3 + b tau^2 + c tau + d
        coef = np.zeros((mids.size, len(funcs), 4))
        for j, f in enumerate(funcs):
            piece = np.clip(np.searchsorted(f.times, mids, side="right") - 1, 0, f.times.size - 2)
            a, b, c, d = f.spline.c[:, piece]
            s = origin - f.times[piece]  # Taylor shift from the piece's knot to u
            shifted = np.stack(
                [a, 3 * a * s + b, (3 * a * s + 2 * b) * s + c, ((a * s + b) * s + c) * s + d],
                axis=-1,
            )
            inside = (mids > f.times[0]) & (mids < f.times[-1])
            coef[inside, j] = shifted[inside]
            # held parts are constant cubics (0, 0, 0, end value): exact, with zero slope
            coef[mids <= f.times[0], j, 3] = f.values[0]
            coef[mids >= f.times[-1], j, 3] = f.values[-1]
        self._knots: list[float] = knots.tolist()
        self._origin: list[float] = origin.tolist()
        self._coef = coef
        self._powers = np.zeros(4)

    def __len__(self) -> int:
        return len(self.names)

    def __getitem__(self, name: str) -> ControlFunction:
        return self.functions[self.index(name)]

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            valid = list(self.names)
            raise UnknownKeyError(
                f"no control function for DOF {name!r}; valid keys: {valid}"
            ) from None

    @property
    def t_start(self) -> float:
        return self._knots[0]

    @property
    def t_end(self) -> float:
        return self._knots[-1]

    def _out(self, out: NDArray[np.float64] | None) -> NDArray[np.float64]:
        if out is None:
            return np.empty(len(self.names))
        if out.shape != (len(self.names),) or out.dtype != np.float64 or not out.flags.c_contiguous:
            raise ConfigError(f"out must be a contiguous float64 array of shape ({len(self)},)")
        return out

    def _tau(self, t: float) -> tuple[int, float]:
        r = bisect.bisect_right(self._knots, t)
        # clamp: held regions are constants, and a finite tau keeps 0 * tau out of NaN
        tau = min(max(t, self._knots[0]), self._knots[-1]) - self._origin[r]
        return r, tau

    def evaluate(self, t: float, out: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Desired angle (rad) or torque (N m) of every DOF at time ``t``, in ``names`` order."""
        out = self._out(out)
        r, tau = self._tau(t)
        p = self._powers
        p[0], p[1], p[2], p[3] = tau * tau * tau, tau * tau, tau, 1.0
        return np.dot(self._coef[r], p, out=out)

    def derivative(self, t: float, out: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Time derivative of every curve at ``t`` (desired velocity); 0 where a curve holds."""
        out = self._out(out)
        r, tau = self._tau(t)
        p = self._powers
        p[0], p[1], p[2], p[3] = 3.0 * tau * tau, 2.0 * tau, 1.0, 0.0
        return np.dot(self._coef[r], p, out=out)

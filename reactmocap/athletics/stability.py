"""The bicycle's self-stability measured from simulation: the uncontrolled bicycle rolls at a
speed from a small roll-and-steer perturbation (the one engine, :func:`~reactmocap.sim.rollout`),
and a linear model fitted to the simulated roll and steer gives the growth rates of its modes;
the weave and capsize speeds are where the weave's and the capsize mode's rates cross zero
(below the weave speed the roll grows in an oscillation, above the capsize speed it grows
slowly without one, between them it decays). Validation against Meijaard et al. (2007):
``docs/athletics.md``."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bicycle import BENCHMARK, Bicycle, BicycleParams, Placement
from reactmocap.athletics.cycling_scene import CyclingScene
from reactmocap.errors import ConfigError
from reactmocap.sim.rollout import RolloutResult, rollout
from reactmocap.sim.world import World, WorldConfig

__all__ = [
    "BICYCLE_WORLD",
    "StabilityPoint",
    "bicycle_world",
    "coast",
    "fit_modes",
    "self_stable_speeds",
    "stability_sweep",
]

F64 = NDArray[np.float64]
#: the bare bicycle's world: a 1 ms step (its fastest mode, the castor, is ~25/s at 10 m/s)
BICYCLE_WORLD = WorldConfig(timestep=0.001, contact_solref=(0.004, 1.0))
#: the perturbation (rad/s of roll rate and of steer rate): small, so the motion stays linear
PERTURBATION = 1e-3
#: the fit uses the motion while the roll stays under this (rad): the linear range
LINEAR_ROLL = 0.02


@dataclass(frozen=True)
class StabilityPoint:
    """What one simulated coast showed at ``speed`` (m/s): the fitted ``eigenvalues`` ``(4,)``
    (1/s), the weave mode (complex, ``nan`` when there is no oscillatory mode) and the capsize
    mode's rate (the slowest real eigenvalue), and whether the roll decays (``stable``)."""

    speed: float
    eigenvalues: NDArray[np.complex128]
    weave: complex
    capsize: float

    @property
    def stable(self) -> bool:
        return bool(np.max(self.eigenvalues.real) < 0.0)


def bicycle_world(params: BicycleParams = BENCHMARK, placement: Placement | None = None,
                  config: WorldConfig = BICYCLE_WORLD) -> tuple[World, Bicycle]:  # fmt: skip
    """A World holding one bicycle (no rider) placed and rolling at ``placement``."""
    bike = Bicycle(params, "bike/", placement or Placement())
    scene = CyclingScene([bike])
    world = World([], config, scene=scene)
    scene.place(world)
    return world, bike


def coast(speed: float, seconds: float, params: BicycleParams = BENCHMARK, *,
          roll_rate: float = PERTURBATION, steer_rate: float = PERTURBATION,
          fps: float = 200.0) -> tuple[RolloutResult, Bicycle]:  # fmt: skip
    """The uncontrolled bicycle rolling for ``seconds`` from upright at ``speed`` with a roll
    and steer rate perturbation; records at ``fps``."""
    if not (math.isfinite(speed) and 0.0 <= speed <= 20.0):
        raise ConfigError(f"speed must be 0-20 m/s, got {speed!r}")
    world, bike = bicycle_world(params, Placement(speed=speed, roll_rate=roll_rate,
                                                  steer_rate=steer_rate))  # fmt: skip
    res = rollout(world, seconds, record_fps=fps, on_unstable="stop")
    return res, bike


def fit_modes(roll: F64, steer: F64, dt: float) -> NDArray[np.complex128]:
    """``(4,)`` continuous-time eigenvalues (1/s) of the linear map that best carries
    ``(roll, steer)`` over two samples to the next (least squares on the samples ``dt`` s
    apart): the lean-and-steer subsystem's four modes."""
    x = np.column_stack([roll, steer])
    x = x / np.maximum(np.abs(x).max(axis=0), 1e-300)  # scale: the fit's conditioning
    a = np.hstack([x[1:-1], x[:-2]])
    b = np.hstack([x[2:], x[1:-1]])
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    ev = np.linalg.eigvals(sol.T).astype(np.complex128)
    return np.sort_complex(np.log(ev) / dt)


def _point(speed: float, ev: NDArray[np.complex128]) -> StabilityPoint:
    osc = ev[np.abs(ev.imag) > 1e-6]
    weave = complex(osc[np.argmax(np.abs(osc.imag))]) if osc.size else complex(np.nan, np.nan)
    real = ev[np.abs(ev.imag) <= 1e-6].real
    capsize = float(real.max()) if real.size else float("nan")
    return StabilityPoint(float(speed), ev, complex(weave.real, abs(weave.imag)), capsize)


def stability_sweep(speeds: Sequence[float], params: BicycleParams = BENCHMARK, *,
                    seconds: float = 4.0, fps: float = 200.0,
                    skip: float = 0.05) -> list[StabilityPoint]:  # fmt: skip
    """For each speed, coast the bicycle ``seconds`` and fit its modes (:func:`fit_modes`) on
    the samples after ``skip`` s (the wheels settling into the ground) while the roll stays
    under :data:`LINEAR_ROLL`."""
    out = []
    for v in speeds:
        res, bike = coast(float(v), seconds, params, fps=fps)
        roll, steer = bike.roll_steer_from_qpos(res.qpos)
        n0 = int(round(skip * fps))
        big = np.flatnonzero(np.abs(roll) > LINEAR_ROLL)
        n1 = int(big[0]) if big.size else roll.size
        if n1 - n0 < 40:
            raise ConfigError(f"the coast at {v} m/s left the linear range too soon to fit")
        out.append(_point(v, fit_modes(roll[n0:n1], steer[n0:n1], 1.0 / fps)))
    return out


def _crossing(speeds: F64, rates: F64, rising: bool) -> float:
    """The speed where ``rates`` crosses zero (linear interpolation), first crossing in the
    given direction; ``nan`` if none."""
    for k in range(len(speeds) - 1):
        a, b = rates[k], rates[k + 1]
        if not (np.isfinite(a) and np.isfinite(b)):
            continue
        if (a < 0 <= b) if rising else (a >= 0 > b):
            return float(speeds[k] + (speeds[k + 1] - speeds[k]) * a / (a - b))
    return float("nan")


def self_stable_speeds(points: Sequence[StabilityPoint]) -> tuple[float, float]:
    """The weave speed (the weave's rate falls through zero) and the capsize speed (the capsize
    mode's rate rises through zero), interpolated between the swept speeds."""
    v = np.array([p.speed for p in points])
    weave = np.array([p.weave.real for p in points])
    capsize = np.array([p.capsize for p in points])
    return _crossing(v, weave, rising=False), _crossing(v, capsize, rising=True)

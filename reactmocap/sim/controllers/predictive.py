"""Predictive sampling (MuJoCo MPC, Howell et al. 2022) on top of the whole-body tracker: every
``segment`` seconds, simulate ``samples`` candidate pelvis requests ``horizon`` seconds ahead with
MuJoCo itself, keep the cheapest. Only the tracker's joint torques act. Why and how it was
tuned: ``docs/design.md``."""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, SimulationError
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from reactmocap.sim.controllers.base import check_params
from reactmocap.sim.controllers.stepping import outside_distance
from reactmocap.sim.controllers.wholebody import WholeBodyPlan, WholeBodyTracker
from reactmocap.sim.world import World

__all__ = ["ANGLE_SCALE", "CAPTURE_SCALE", "FALL_PENALTY", "POSITION_SCALE", "PredictiveTracker"]

F64 = NDArray[np.float64]

#: pelvis position error (m) that costs 1 (the tracking benchmark's tolerance)
POSITION_SCALE = 0.10
#: pelvis angle error (rad) that costs 1 (the tracking benchmark's tolerance)
ANGLE_SCALE = float(np.radians(15.0))
#: MuJoCo's divergence warnings (each resets the simulation)
_DIVERGED = [
    int(w)
    for w in (
        mujoco.mjtWarning.mjWARN_BADQPOS,
        mujoco.mjtWarning.mjWARN_BADQVEL,
        mujoco.mjtWarning.mjWARN_BADQACC,
        mujoco.mjtWarning.mjWARN_BADCTRL,
    )
]
#: cost of one scored sample with the pelvis below half its start height
FALL_PENALTY = 100.0
#: capture point distance (m) outside the sole corners on the floor that costs
#: ``capture_weight``
CAPTURE_SCALE = 0.05
#: a sole corner this close to the floor (m) supports the body in the capture point term
_SUPPORT_TOUCH = 0.02


def _quiet(message: str) -> None:
    del message


def _diverged_count(d: mujoco.MjData) -> NDArray[np.int64]:
    return np.array([d.warning[w].number for w in _DIVERGED], dtype=np.int64)


class PredictiveTracker:
    """``tracker`` with its pelvis request chosen by predictive sampling (see the module
    docstring); it ticks with the tracker, in its place.

    Args:
        tracker: the whole-body tracker to steer.
        segment: seconds between plans (each plan's choice is held this long).
        horizon: seconds each candidate is simulated ahead (>= ``segment``).
        samples: candidates per plan (>= 2: the last choice and zero come first).
        sigma_position, sigma_rotation: standard deviation of the perturbations of the
            pelvis request (m/s^2 linear, rad/s^2 angular).
        cost_dt: seconds between scored samples of a prediction.
        seed: seed of the candidate generator.
        capture_weight: weight of a cost term on the simulated capture point's distance
            outside the sole corners on the floor (per :data:`CAPTURE_SCALE`, squared; no
            corner down: no term; 0: off): the pelvis error alone sees a fall only once the
            pelvis has moved. Measured on whole clips (``docs/tracking.md``, "Twelfth
            pass"): it moved falls by seconds either way; off by default.

    Defaults were chosen on the benchmark windows (``benchmarks/bench_sim.py``): the defaults
    tracked 88% of them (the tracker alone 80%); 12 or 16 samples also 88%, at 1.5-2x the
    cost; a 0.3 s horizon with 10 samples and twice the perturbation 78%.
    """

    def __init__(
        self,
        tracker: WholeBodyTracker,
        *,
        segment: float = 0.1,
        horizon: float = 0.5,
        samples: int = 8,
        sigma_position: float = 1.0,
        sigma_rotation: float = 10.0,
        cost_dt: float = 0.05,
        seed: int = 0,
        capture_weight: float = 0.0,
    ) -> None:
        dt = tracker.world.timestep
        for name, value in (("segment", segment), ("horizon", horizon), ("cost_dt", cost_dt)):
            if not (np.isfinite(value) and value >= dt):
                raise ConfigError(f"{name} must be at least one time step ({dt} s), got {value!r}")
        if horizon < segment:
            raise ConfigError(f"horizon ({horizon} s) must be at least segment ({segment} s)")
        if samples < 2:
            raise ConfigError(f"samples must be >= 2 (the last choice and zero), got {samples!r}")
        check_params(
            {"sigma_position": sigma_position, "sigma_rotation": sigma_rotation,
             "capture_weight": capture_weight}
        )  # fmt: skip
        self.capture_weight = float(capture_weight)
        self.tracker = tracker
        self.world = tracker.world
        self.segment = float(segment)
        self.samples = int(samples)
        self.control_every = tracker.control_every
        self.seed = int(seed)
        self.sigma = np.r_[np.full(3, sigma_position), np.full(3, sigma_rotation)]
        self._rng = np.random.default_rng(seed)
        self._horizon_steps = round(horizon / dt)
        self._cost_steps = max(1, round(cost_dt / dt))
        self._next = 0.0
        self._warnings = np.zeros(len(_DIVERGED), dtype=np.int64)
        wc = tracker.wc
        self._qpos = wc.qpos_slice
        self._z0 = float(self.world.data.qpos[self._qpos][2])
        #: ``(6,)`` the pelvis request in force (see ``WholeBodyTracker.root_bias``)
        self.choice = np.zeros(6)
        #: cost of each candidate of the last plan (the chosen one is the minimum)
        self.last_costs = np.zeros(0)

    @property
    def last_plan(self) -> WholeBodyPlan | None:
        return self.tracker.last_plan

    def cost(self, t: float) -> float:
        """Cost of the current state at rollout time ``t`` (one scored sample)."""
        q_ref = self.tracker.reference(t)[0]
        q = self.world.data.qpos[self._qpos]
        pos = float(np.linalg.norm(q[:3] - q_ref[:3])) / POSITION_SCALE
        rel = quat_mul(quat_conj(q[3:7]), q_ref[3:7])
        ang = float(np.linalg.norm(quat_log(rel if rel[0] >= 0 else -rel))) / ANGLE_SCALE
        fallen = FALL_PENALTY if q[2] < 0.5 * self._z0 else 0.0
        total = pos * pos + ang * ang + fallen
        if self.capture_weight:
            corners = self.tracker.sole_corners().reshape(-1, 3)
            down = corners[:, 2] - self.tracker.floor_z < _SUPPORT_TOUCH
            if down.any():
                xi, _ = self.tracker.capture_point()
                out = max(outside_distance(xi, corners[down, :2]), 0.0) / CAPTURE_SCALE
                total += self.capture_weight * out * out
        return total

    def _diverged(self, d: mujoco.MjData) -> bool:
        # a reset zeroes the counters before counting its warning, so compare for change
        return bool(np.any(_diverged_count(d) != self._warnings))

    def _predict(self, bias: F64, t: float) -> float:
        """Run the tracker with ``bias`` for the horizon from the current state; its cost
        (infinite if the simulation diverges)."""
        d = self.world.data
        dt = self.world.timestep
        t0 = float(d.time)
        self.tracker.root_bias[:] = bias
        total = 0.0
        k = 0
        while k < self._horizon_steps:
            if k % self.control_every == 0:
                try:
                    self.tracker.control(self.world, t + k * dt)
                except SimulationError:
                    return np.inf
            every = self.control_every
            n = min(every - k % every, self._cost_steps - k % self._cost_steps)
            self.world.step(n)
            k += n
            # MuJoCo resets a diverged simulation (rewinding the clock) and counts a warning
            if d.time < t0 + (k - 0.5) * dt or self._diverged(d):
                return np.inf
            if k % self._cost_steps == 0:
                total += self.cost(t + k * dt)
        return total if np.isfinite(total) else np.inf

    def plan(self, t: float) -> None:
        """Choose :attr:`choice` by predicting from the current state; leaves the state as
        it found it."""
        world = self.world
        state = world.get_state()
        memory = self.tracker.memory()
        d = world.data
        self._warnings = _diverged_count(d)
        noise = self.sigma * self._rng.standard_normal((self.samples - 2, 6))
        candidates = np.concatenate([self.choice[None], np.zeros((1, 6)), self.choice + noise])
        costs = np.empty(len(candidates))
        # a discarded candidate may diverge: keep MuJoCo's printed warnings (and its log file)
        # for the real simulation
        handler = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(_quiet)
        try:
            for i, bias in enumerate(candidates):
                world.set_state(state)
                self.tracker.restore(memory)
                costs[i] = self._predict(bias, t)
        finally:
            mujoco.set_mju_user_warning(handler)
            world.set_state(state)
            self.tracker.restore(memory)
            for w, n in zip(_DIVERGED, self._warnings):
                d.warning[w].number = n
        self.last_costs = costs
        self.choice = candidates[int(np.argmin(costs))].copy()

    def scale_gains(self, scale: float) -> None:
        self.tracker.scale_gains(scale)

    def hold(self, t: float) -> None:
        self.tracker.hold(t)

    def reset(self, world: World) -> None:
        self.tracker.reset(world)
        self._rng = np.random.default_rng(self.seed)
        self._next = 0.0
        self.choice = np.zeros(6)
        self._z0 = float(world.data.qpos[self._qpos][2])

    def control(self, world: World, t: float) -> None:
        if t >= self._next - 1e-9:
            self._next = t + self.segment
            self.plan(t)
        self.tracker.root_bias[:] = self.choice
        self.tracker.control(world, t)

"""The paper's tracking controller: the inertia-scaled PD servo pulled toward a reference's joint
rotations (Zordan et al. 2005), and its passive counterpart (servo off: a ragdoll)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from reactmocap.library.motion import Motion
from reactmocap.sim.character import BALL_JOINTS
from reactmocap.sim.controllers.base import check_character, check_params
from reactmocap.sim.reference import ReferencePath, as_path
from reactmocap.sim.servo import critical_kv
from reactmocap.sim.world import World

__all__ = ["PDTracker", "Passive"]

F64 = NDArray[np.float64]
NJ = len(BALL_JOINTS)


class PDTracker:
    """Servo targets of one character = the reference's ball-joint rotations at clip time
    ``start + t`` (normalised linear blend of the neighbouring frames, sign-continuous: within
    0.2% of slerp at 30 fps), with gains ``kp``, ``kv`` (``None``: critical)."""

    def __init__(
        self,
        world: World,
        character: int,
        reference: Motion | ReferencePath,
        start: float = 0.0,
        *,
        kp: float,
        kv: float | None = None,
        control_every: int,
        refresh_every: int,
    ) -> None:
        check_character(world, character)
        check_params({"kp": kp, "kv": kv})
        self.character = character
        self.kp = float(kp)
        self.kv = kv
        self.control_every = int(control_every)
        self.refresh_every = int(refresh_every)
        path = as_path(world, character, reference)
        self.path = path
        self.clock = path.clock(start)
        self.quats = path.q[:, 7:].reshape(path.num_frames, NJ, 4)
        self._buf = np.empty((NJ, 4))
        self._scale = 1.0
        self._applied = 1.0

    def scale_gains(self, scale: float) -> None:
        """Stiffness times ``scale`` (damping times its square root, staying critical) from
        the next tick on: a gain schedule, e.g. yielding to an impact."""
        self._scale = float(scale)

    def targets_at(self, t: float) -> F64:
        i0, i1, a = self.clock.bracket(t)
        np.multiply(self.quats[i0], 1.0 - a, out=self._buf)
        self._buf += a * self.quats[i1]
        return self._buf

    def hold(self, t: float) -> None:
        """From rollout time ``t`` on, follow the reference's pose at ``t``."""
        self.clock = self.clock.held_from(t)

    def reset(self, world: World) -> None:
        servo = world.servo
        servo.enable(self.character, on=True)
        self._set_gains(world)
        servo.refresh_every = self.refresh_every

    def _set_gains(self, world: World) -> None:
        kv = critical_kv(self.kp) if self.kv is None else self.kv
        s = self._scale
        world.servo.set_gains(self.kp * s, kv * np.sqrt(s), self.character)
        self._applied = s

    def control(self, world: World, t: float) -> None:
        if self._scale != self._applied:
            self._set_gains(world)
        world.servo.set_targets(self.character, self.targets_at(t))


class Passive:
    """The character's servo off: joint damping and limits only (a ragdoll)."""

    def __init__(self, world: World, character: int, *, control_every: int) -> None:
        check_character(world, character)
        self.character = character
        self.control_every = int(control_every)

    def reset(self, world: World) -> None:
        if world.has_servo:
            world.servo.enable(self.character, on=False)

    def control(self, world: World, t: float) -> None:
        del world, t

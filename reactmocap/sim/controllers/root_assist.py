"""NON-PHYSICAL root stabilisation ("hand of god"), off unless asked for: an external wrench on
the pelvis toward the reference pelvis. Reports say when it was used."""

from __future__ import annotations

from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from reactmocap.sim.controllers.base import check_character, check_params
from reactmocap.sim.reference import ReferencePath, as_path
from reactmocap.sim.servo import critical_kv
from reactmocap.sim.world import World

__all__ = ["RootAssist"]


class RootAssist:
    """``F = M (kp (p_d - p) - kv (v - v_d))`` and ``tau = I (kp e - kv w)`` on the pelvis, with
    ``M`` the character's mass and ``I`` a scale of its inertia about the pelvis (``0.1 M``).
    Its explicit PD on the light pelvis goes unstable when held for several steps: it ticks
    every step."""

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
    ) -> None:
        check_character(world, character)
        check_params({"kp": kp, "kv": kv})
        wc = world.characters[character]
        path = as_path(world, character, reference)
        self.clock = path.clock(start)
        self.pos = path.q[:, :3]
        self.rot = path.q[:, 3:7]
        # velocity feed-forward: without it a PD lags a walking pelvis by kv v / kp
        self.vel = path.v[:, :3]
        self.kp = float(kp)
        self.kv = critical_kv(kp) if kv is None else float(kv)
        self.bid = int(wc.body_ids[0])
        self.mass = float(world.model.body_subtreemass[self.bid])
        self.dof = wc.dof_adr
        self.control_every = int(control_every)

    def reset(self, world: World) -> None:
        del world

    def control(self, world: World, t: float) -> None:
        d = world.data
        i = self.clock.nearest(t)
        p_d, q_d = self.pos[i], self.rot[i]
        v = d.qvel[self.dof : self.dof + 3]
        w_local = d.qvel[self.dof + 3 : self.dof + 6]
        e = quat_log(quat_mul(quat_conj(d.xquat[self.bid]), q_d))  # body frame
        tau_local = 0.1 * self.mass * (self.kp * e - self.kv * w_local)
        rot = d.xmat[self.bid].reshape(3, 3)
        d.xfrc_applied[self.bid, :3] = self.mass * (
            self.kp * (p_d - d.xpos[self.bid]) - self.kv * (v - self.vel[i])
        )
        d.xfrc_applied[self.bid, 3:] = rot @ tau_local

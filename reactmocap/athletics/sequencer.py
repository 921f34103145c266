"""The sequencer: basis controllers run one after another as one engine controller. Their states
join one :class:`~reactmocap.sim.controllers.StateMachine` (named ``basis.state``); an exit to
:data:`~reactmocap.athletics.machine.NEXT` enters the next basis controller's first state, and
the state carries over through the shared context (the rig's targets, gains and the hand-over
dict), so a transition never jumps. Each tick: measure, take a transition, run the state's
law, write the servo, log."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from reactmocap.athletics.machine import NEXT, Basis, Context
from reactmocap.errors import ConfigError
from reactmocap.rotations import wrap_angle
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import State, StateMachine
from reactmocap.sim.world import World

__all__ = ["Sequencer", "somersault_pitch"]

NJ = len(BALL_JOINTS)


class Sequencer:
    """Runs ``bases`` in order on ``ctx`` (an engine controller: give it to ``rollout``)."""

    def __init__(self, ctx: Context, bases: Sequence[Basis]) -> None:
        if not bases:
            raise ConfigError("a sequence needs at least one basis controller")
        self.ctx = ctx
        self.bases = tuple(bases)
        self.control_every = ctx.control_every
        names = [b.name for b in self.bases]
        prefixes = [n if names.count(n) == 1 else f"{n}{i}" for i, n in enumerate(names)]
        states: list[State] = []
        for i, (basis, pre) in enumerate(zip(self.bases, prefixes)):
            nxt = f"{prefixes[i + 1]}.{self.bases[i + 1].initial}" if i + 1 < len(bases) else None
            for st in basis.states(ctx):
                exits = []
                for event, target in st.exits:
                    if target == NEXT:
                        if nxt is not None:
                            exits.append((event, nxt))
                    else:
                        exits.append((event, f"{pre}.{target}"))
                states.append(State(f"{pre}.{st.name}", st.law, st.on_enter, tuple(exits)))
        self.machine = StateMachine(states, f"{prefixes[0]}.{self.bases[0].initial}",
                                    ctx.control_every)  # fmt: skip
        dofs = ctx.rig.wc.ball_dof_start
        self._dofs = slice(dofs, dofs + 3 * NJ)
        self._head = ctx.senses.body("head")
        self._trunk = 0.0
        self._trunk_dir = np.array([0.0, 0.0, 1.0])
        self._t = 0.0

    @property
    def state(self) -> str:
        return self.machine.current.name

    @property
    def transitions(self):  # type: ignore[no-untyped-def]
        return self.machine.transitions

    def reset(self, world: World) -> None:
        self.ctx.rig.reset()
        self.ctx.senses.time = -1.0
        self.ctx.rotation = self.ctx.twist = 0.0
        self.ctx.heading0 = None
        self.machine.reset(world)

    def control(self, world: World, t: float) -> None:
        ctx = self.ctx
        s = ctx.sense(t)
        d = world.data
        self._turn(d, s, t)
        self.machine.control(world, t)
        ctx.rig.apply(t)
        tau = (d.qfrc_actuator[self._dofs] + d.qfrc_applied[self._dofs]
               + d.qfrc_damper[self._dofs]).reshape(NJ, 3)  # fmt: skip
        w = d.qvel[self._dofs].reshape(NJ, 3)
        ctx.log.rows.append((t, s.com.copy(), s.com_vel.copy(), s.grf.copy(),
                             int(s.foot_contact.sum()), self.machine.current.name))  # fmt: skip
        ctx.log.torques.append(np.linalg.norm(tau, axis=1))
        ctx.log.powers.append(np.einsum("ij,ij->i", tau, w))
        ctx.log.others.append(bool(s.other_contact))
        ctx.log.momentum.append(d.subtree_angmom[s.root].copy())
        centre = s.support_center()
        ctx.log.offsets.append(float(np.hypot(*(s.com[:2] - centre[:2]))))
        # above the floor plane, along its normal: on a slope a body that slides down it
        # upright has not fallen (on a level floor through z = 0 this is the world z)
        ctx.log.pelvis.append(float((d.xpos[s.root] - d.geom_xpos[s.floor]) @ s.floor_normal))
        ctx.log.rotation.append(ctx.rotation)
        ctx.log.twist.append(ctx.twist)
        ctx.log.trunk.append(self._trunk_dir)

    def _turn(self, d, s, t: float) -> None:  # type: ignore[no-untyped-def]
        """Update the somersault rotation (the pelvis-to-head line's pitch in the first
        tick's sagittal plane, unwrapped) and the twist (the pelvis's angular velocity about
        that line, integrated)."""
        ctx = self.ctx
        trunk = d.xpos[self._head] - d.xpos[s.root]
        trunk = trunk / max(float(np.linalg.norm(trunk)), 1e-9)
        self._trunk_dir = trunk
        if ctx.heading0 is None:
            ctx.heading0 = s.heading()
            self._trunk = somersault_pitch(trunk, ctx.heading0)
            self._t = t
        a = somersault_pitch(trunk, ctx.heading0)
        ctx.rotation += wrap_angle(a - self._trunk)
        self._trunk = a
        ctx.twist += float(d.cvel[s.root, :3] @ trunk) * (t - self._t)
        self._t = t


def somersault_pitch(trunk: np.ndarray, heading: float) -> float:
    """Pitch (rad, ``(-pi, pi]``, 0 upright, > 0 forward) of the direction ``trunk`` in the
    sagittal plane of ``heading``."""
    fwd = float(trunk[0] * math.cos(heading) + trunk[1] * math.sin(heading))
    return math.atan2(fwd, float(trunk[2]))

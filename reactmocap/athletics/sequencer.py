"""The sequencer: basis controllers run one after another as one engine controller. Their states
join one :class:`~reactmocap.sim.controllers.StateMachine` (named ``basis.state``); an exit to
:data:`~reactmocap.athletics.machine.NEXT` enters the next basis controller's first state, and
the state carries over through the shared context (the rig's targets, gains and the hand-over
dict), so a transition never jumps. Each tick: measure, take a transition, run the state's
law, write the servo, log."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from reactmocap.athletics.machine import NEXT, Basis, Context
from reactmocap.errors import ConfigError
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.controllers.machine import State, StateMachine
from reactmocap.sim.world import World

__all__ = ["Sequencer"]

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

    @property
    def state(self) -> str:
        return self.machine.current.name

    @property
    def transitions(self):  # type: ignore[no-untyped-def]
        return self.machine.transitions

    def reset(self, world: World) -> None:
        self.ctx.rig.reset()
        self.ctx.senses.time = -1.0
        self.machine.reset(world)

    def control(self, world: World, t: float) -> None:
        ctx = self.ctx
        s = ctx.sense(t)
        self.machine.control(world, t)
        ctx.rig.apply(t)
        d = world.data
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
        ctx.log.pelvis.append(float(d.xpos[s.root][2]))

"""The balance basis controller as a registered engine controller (``"athletic_balance"`` in
:data:`reactmocap.sim.controllers.CONTROLLERS`): any character of any World stands balanced,
whatever clip it was given (the thesis's balance does not follow a clip)."""

from __future__ import annotations

from typing import Any

from reactmocap.sim.controllers.base import Controller
from reactmocap.sim.world import World

__all__ = ["athletic_balance"]


def athletic_balance(
    world: World, character: int, reference: Any, start: float, params: dict[str, Any]
) -> Controller:
    """Registry factory: the thesis's balance (ch. 7) for ``character``; ``reference`` and
    ``start`` are not used. Options: ``pitch`` (rad), ``leg`` (fraction), ``com_offset_x``,
    ``com_offset_y`` (m)."""
    from reactmocap.athletics.balance import Balance, Posture
    from reactmocap.athletics.bodies import athlete_of
    from reactmocap.athletics.machine import Context
    from reactmocap.athletics.sequencer import Sequencer

    del reference, start
    ath = athlete_of(world.characters[character].character)
    posture = Posture(
        pitch=float(params.get("pitch", 0.0)),
        leg=float(params.get("leg", Posture().leg)),
        com_offset=(float(params.get("com_offset_x", 0.0)), float(params.get("com_offset_y", 0.0))),
    )
    ctx = Context.make(world, ath, character, control_every=int(params["control_every"]))
    return Sequencer(ctx, [Balance(posture)])

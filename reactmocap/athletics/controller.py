"""The athletic controllers as registered engine controllers (in
:data:`reactmocap.sim.controllers.CONTROLLERS`): ``"athletic_balance"``, any character of any
World stands balanced whatever clip it was given (the thesis's balance does not follow a clip);
``"bicycle_rider"``, the character rides the bicycle it is mounted on in a cycling World (the
rider of Hodgins et al. 1995, eqs. 7-11; a clip is not followed either)."""

from __future__ import annotations

from typing import Any

from reactmocap.sim.controllers.base import Controller
from reactmocap.sim.world import World

__all__ = ["athletic_balance", "bicycle_rider"]


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


def bicycle_rider(
    world: World, character: int, reference: Any, start: float, params: dict[str, Any]
) -> Controller:
    """Registry factory: :class:`~reactmocap.athletics.rider.Rider` for ``character`` on the
    bicycle its mount ties it to (``world.scene`` a
    :class:`~reactmocap.athletics.cycling_scene.CyclingScene`, as
    :func:`reactmocap.athletics.cycling.setup` builds); ``reference`` and ``start`` are not
    used. Options: the Rider's ``speed`` (m/s) and ``heading`` (rad) commands, ``kp``,
    ``arm_scale``, ``leg_scale``."""
    from reactmocap.athletics.cycling_scene import CyclingScene
    from reactmocap.athletics.rider import Rider, RiderMount
    from reactmocap.errors import ConfigError

    del reference, start
    scene = world.scene
    if not isinstance(scene, CyclingScene):
        raise ConfigError("bicycle_rider needs a World built with a CyclingScene (cycling.setup)")
    mounts = [p for p in scene.parts if isinstance(p, RiderMount)]
    bikes = [k for k, c in enumerate(scene.riders) if c == character]
    mount = next((m for m in mounts if bikes and m.bicycle is scene.bicycles[bikes[0]]), None)
    if mount is None:
        raise ConfigError(f"character {character} is not mounted on a bicycle in this world")
    return Rider(world, mount.athlete, mount.bicycle, mount, character, **params)

"""The built-in composed maneuvers (thesis ch. 8): the standing somersaults and the platform
dives, each a :class:`~reactmocap.athletics.maneuvers.Maneuver` of basis controllers run by
:func:`~reactmocap.athletics.maneuvers.run_maneuver`, with their reports (rotation, twist,
landed or entered cleanly)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any

from reactmocap.athletics.behaviours import AthleticsResult
from reactmocap.athletics.bodies import athlete
from reactmocap.athletics.dive import PLATFORM_MAX, stretch_angles
from reactmocap.athletics.maneuvers import Maneuver, Phase, run_maneuver
from reactmocap.athletics.scene import DEFAULT_CONTACT
from reactmocap.athletics.tumble import POSITIONS, somersault_inertia
from reactmocap.errors import ConfigError, UnknownKeyError

__all__ = [
    "DIRECTIONS",
    "DIVE_DIRECTIONS",
    "DIVE_TWISTS",
    "PLATFORM_MAX",
    "SETTLED_START",
    "PRESET_STARTS",
    "SETTLED_START_STANDING",
    "SOMERSAULT_PRESETS",
    "TIMED_START",
    "TWIST_DIVE",
    "TWIST_SOMERSAULT_PRESETS",
    "dive",
    "dive_maneuver",
    "HANDSPRING_BODY_PRESET",
    "HANDSPRING_PRESET",
    "HANDSPRING_SECONDS",
    "HANDSPRING_STARTS",
    "SETTLE_SECONDS",
    "handspring",
    "handspring_maneuver",
    "somersault",
    "somersault_maneuver",
]


# ---------------------------------------------------------------------------------- somersaults
#: a maneuver's settled start: a perturbed start is settled onto both feet, flat, with the COM
#: still over them (``plant``) before the next phase begins, and a start not settled within 3 s
#: fails there (report ``unsettled_s``) instead of leaping wild (docs/athletics.md, capture
#: regions). The somersaults' first phase; the maneuver files that start settled
#: (``vertical_leap.toml``, ``back_somersault.toml``) write the same phase (a test holds them
#: to it)
SETTLED_START = Phase("balance", "settled", MappingProxyType({"plant": True}), 3.0)
#: :data:`SETTLED_START` with the standing behaviour's hip and arm strategies against a fall
#: (``gains = "standing"``): the female back tuck's perturbed starts that stood with the COM
#: ~9 cm behind the feet's middle fell backward while settling under the ankles alone
#: (docs/athletics.md); ``back_somersault_female.toml`` writes the same phase
SETTLED_START_STANDING = Phase("balance", "settled",
                               MappingProxyType({"plant": True, "gains": "standing"}), 3.0)  # fmt: skip
#: the timed start: the next phase begins 0.3 s into the start, settled or not (the dives, the
#: handspring but the male's (:data:`HANDSPRING_STARTS`) and the timed entries of
#: :data:`PRESET_STARTS`)
TIMED_START = Phase("balance", "after", MappingProxyType({}), 0.3)
#: seconds a run from :data:`SETTLED_START` is simulated beyond one from :data:`TIMED_START`:
#: what the settle may take beyond the timed start's 0.3 s
SETTLE_SECONDS = 2.7
#: seconds a somersault is simulated: from :data:`TIMED_START` 5.5; from :data:`SETTLED_START`
#: :data:`SETTLE_SECONDS` more (8.2, as ``back_somersault.toml``)
SOMERSAULT_SECONDS = MappingProxyType({"after": 5.5, "settled": 5.5 + SETTLE_SECONDS})
#: the :data:`SOMERSAULT_PRESETS` entries (``body/key``) that do not start from
#: :data:`SETTLED_START`, and their start (the twisting presets keep the timed start: settled,
#: the full twist's perturbed starts landed 0 of 29 at full size, against 2/50:
#: docs/athletics.md, 2026-12-02). The female backward presets and, since 2026-12-05, the male
#: forward tuck settle with the standing gains (:data:`SETTLED_START_STANDING`): leaping 0.3 s
#: into the start, 7 of the tuck's 16 full-size failures (seed 0) crouched on one foot, and
#: starts with the COM 7-10 cm behind the feet fell backward settling under the ankles alone.
PRESET_STARTS: Mapping[str, Phase] = MappingProxyType({
    "male/forward": SETTLED_START_STANDING, "female/backward": SETTLED_START_STANDING,
})  # fmt: skip
#: the built-in somersaults, tuned by hand (as the thesis's, section 8.4) per body:
#: body -> ``direction`` or ``direction/position`` -> (leap, tumble, landing parameters); a
#: position with no preset of its own uses its direction's (the tuck's) leap and landing with
#: the position's own inertia. The back pike needs more momentum for its larger inertia
#: (aiming at -66 kg m^2/s with the hips' feedback allowed 1.3 rad, it gets -59.6 against the
#: tuck's -49), opens earlier (lead 3.4 rad) and reaches for the floor with the knees bent
#: 1.0 rad (at 0.6 its straight-legged touchdown bounced). The forward preset (male) crouches with
#: the arms overhead, the COM 5 cm ahead of the feet (moved there over the crouch), and pushes
#: with the "com" servo, whose centre of pressure steers the take-off momentum to +49 kg m^2/s
#: (since 2026-12-03; the timed push, aimed at +60 with the hips' feedback, hopped off the
#: floor as it began and left in two modes, +43 or +34); it stays tucked until the prediction
#: reaches the full turn less 0.45 rad, so the legs reach the floor out, extending hips and
#: knees 60% toward the landing pose first (thesis 8.5.1), and lands with the feet 4 cm ahead
#: of the capture point, knees bent 0.5 rad (docs/athletics.md). Since 2026-12-03 its push
#: also moves the weight between the feet against the cartwheel momentum (the leap's
#: ``roll_gain``) and its legs' sideways aim is taken from the pelvis's whole orientation
#: (``aim_sideways``): a perturbed start's small roll grew over the push, and the feet touched
#: down staggered and to one side of the COM; it stood up on one foot and fell. Since
#: 2026-12-03 16:04 UTC its landing eases a pelvis rolled 0.5 rad or more at touchdown to
#: upright over 0.3 s (``roll_ease``, ``roll_min``): righted at once, the reaction lifted one
#: foot and the body stood up on the other, turned about the vertical and fell. The back
#: layout (inertia 18.5 kg m^2 against the tuck's 4.7) needs the leap at effort 0.9 aiming at
#: -90 kg m^2/s with the hips allowed 1.5 rad (it gets -77.0, 1.2 m of COM rise); it holds the
#: layout until the rotation predicted for the touchdown comes down to the turn less 0.96 rad
#: (the landing's reach pikes the body to put the feet under it, and pikes deeper the longer
#: it has: its turn is predicted as L / 4.0 kg m^2 over the time to touchdown less 0.217 s,
#: ``open_delay``; since 2026-12-03, before L / 8.0 over all of it), and lands with the knees bent
#: 1.0 rad, the feet 13 cm behind the capture point (landed at 12-13 cm, not 15 or 17). The
#: maneuver file also moves the feet in the reach's last 50 ms by the rotation predicted at
#: touchdown (``turn_gain``, since 2026-12-03); this preset, which starts settled, does not:
#: with it 23/50 at a tenth (seed 0), without 24/50 (docs/athletics.md). At
#: effort 0.8 (before 2026-12-02) the opening sat at the edge where the reach, opened short of
#: inverted, folds the body into a deep pike and turns it over: perturbed starts, a little
#: short of the nominal's momentum, opened a few degrees earlier and over-rotated by 200.
#: The back tuck lands with the feet 17 cm behind the capture point and the legs' sideways aim
#: taken from the pelvis's whole orientation (``aim_sideways``: a perturbed take-off rolls the
#: body, and feet landing to one side of the COM left it on one foot; since 2026-12-02 its
#: perturbed starts land 33/50 at full size, from 19, and 50/50 at a tenth, from 41), and its
#: reach holds the legs' aim in the world while the body still turns (``spin_aim``: the feet
#: were still swinging forward at 3-5 m/s when they touched; since 2026-12-02 44/50 at full
#: size, seed 0). The female back tuck reaches the same way (``spin_aim``; chosen on the nominal
#: alone: lead 3.2-4.0 and delta -0.12/-0.16 land at 4 of the 6 corners, lead 3.6 / delta
#: -0.16 in the middle; before, lead 3.2 and delta -0.12 were the only landing one of six):
#: 41/50 at a tenth from 22, 9/50 at full size from 2 (seed 0, 2026-12-02). Since 2026-12-03 her
#: legs' sideways aim is taken from where the pelvis will be once the hips get there
#: (``aim_sideways`` with ``twist_aim``): a take-off's cartwheel momentum twists her opening body
#: about its long axis at ~4 rad/s, her feet touched down 10-17 cm to the side of the COM and
#: she stood up on one foot and fell sideways (docs/athletics.md). Since 2026-12-03 her push
#: also servos the cartwheel and yaw momentum to zero (the leap's ``tilt_gain``): the
#: take-off's yaw momentum told her landings apart. Since 2026-12-03 her arms spread in the
#: reach against the twist the opening body makes (``twist_arms``; 25 since 2026-12-03 12:48
#: UTC, fully spread from 1.7 kg m^2/s: at 15 starts that still twisted fell sideways),
#: and her legs absorb the touchdown pushing from the feet that carry the weight
#: (``stance_push``). Since 2026-12-03 her
#: feet land farther ahead after a weak take-off (``momentum_gain`` with ``momentum_side``):
#: placed for her usual spin, they stopped a smaller one too hard and she fell forward.
SOMERSAULT_PRESETS: Mapping[
    str, Mapping[str, tuple[Mapping[str, float | str], Mapping[str, float], Mapping[str, float | list[float]]]]
] = MappingProxyType({
    "male": MappingProxyType({
        "backward": (MappingProxyType({"effort": 0.6, "spin": -55.0, "spin_limit": 1.0}),
                     MappingProxyType({"lead": 2.8}),
                     MappingProxyType({"delta": -0.17, "aim_sideways": True,
                                       "spin_aim": True})),
        "backward/pike": (MappingProxyType({"effort": 0.6, "spin": -66.0, "spin_limit": 1.3}),
                          MappingProxyType({"lead": 3.4}),
                          MappingProxyType({"delta": -0.15, "knee": 1.0})),
        "backward/layout": (MappingProxyType({"effort": 0.9, "spin": -90.0, "spin_limit": 1.5}),
                            MappingProxyType({"lead": -0.96, "open_inertia": 4.0,
                                              "open_delay": 0.217}),
                            # a start whose feet are over 0.15 m from the COM 24 ms into
                            # the reach touches down too little turned and puts them 2 cm
                            # farther ahead (LandingParams.late_delta, as back_layout.toml:
                            # a tenth 24 -> 29 and 17 -> 28 of 50 on seeds 0 and 1, full
                            # size 5 -> 5, 2026-12-04; docs/athletics.md). A list: a
                            # maneuver file's numbers load as one
                            MappingProxyType({"delta": -0.13, "knee": 1.0,
                                              "late_delta": [0.024, 0.15, -0.11]})),
        "forward": (MappingProxyType({"effort": 1.0, "push": "com", "rise": 0.85, "leg": 0.6,
                                      "pitch": 0.0, "lean": 0.0, "push_hip": 0.5,
                                      "push_ankle": 1.0, "spin": 49.0, "com_offset": 0.05,
                                      "com_ease": True, "arms_back": -2.8, "arms": 0.0,
                                      "roll_gain": 15.0, "push_both": True,
                                      "hold": 0.25}),
                    MappingProxyType({"lead": 0.45, "latest": 0.0, "extend": 0.6,
                                      "extend_lead": 0.15}),
                    MappingProxyType({"delta": 0.04, "knee": 0.5, "restore": 0.4,
                                      "damping": 1.75, "aim_sideways": True,
                                      "roll_ease": 0.3, "roll_min": 0.5})),
    }),
    "female": MappingProxyType({
        "backward": (MappingProxyType({"effort": 0.6, "spin": -26.0, "spin_limit": 1.0,
                                       "tilt_gain": 10.0}),
                     MappingProxyType({"lead": 3.6}),
                     MappingProxyType({"delta": -0.16, "spin_aim": True, "aim_sideways": True,
                                       "twist_aim": True, "twist_arms": 25.0,
                                       "stance_push": True, "momentum_gain": 0.015,
                                       "momentum_ref": -23.0, "momentum_side": True})),
    }),
})  # fmt: skip
DIRECTIONS = ("backward", "forward")
#: the twisting somersaults built (thesis 5.2's tilt twist, initiated in the air), tuned by
#: hand (2026-12-02, docs/athletics.md): body -> ``direction/position`` -> twist turns ->
#: (leap, tumble, landing parameters). The male back layout with one twist: the arms are
#: thrown 1.8 rad the same way about the body's front-back axis 0.05 s after lift-off (over
#: 0.08 s) and brought back once the predicted twist reaches the full turn, which takes the
#: tilt out and stops the twist (a half twist cannot be stopped this way: its undo runs past
#: the shoulders' cones). The twist costs the layout's flight its opening: the tumble opens
#: only once the throw is undone (its lead 1.5 rad already asks to open by then), 0.3 s before
#: touchdown. So the leap makes more somersault momentum than the untwisted layout's (effort
#: 1.0, aimed at -95 kg m^2/s with the hips allowed 2.0 rad: it gets -94.5, against -77):
#: the body turns faster through the twist and the reach (at -79 the touchdown came at -275
#: deg, at -99 at -311..-331: both fell), and lands with the feet 12 cm behind the capture
#: point (landed at 11-13 cm, fell at 14-15). Narrow: docs/athletics.md.
TWIST_SOMERSAULT_PRESETS: Mapping[
    str, Mapping[str, Mapping[float, tuple[Mapping[str, float], Mapping[str, float],
                                           Mapping[str, float]]]]
] = MappingProxyType({
    "male": MappingProxyType({
        "backward/layout": MappingProxyType({
            1.0: (MappingProxyType({"effort": 1.0, "spin": -95.0, "spin_limit": 2.0}),
                  MappingProxyType({"lead": 1.5, "open_inertia": 8.0, "arm_tilt": 1.8,
                                    "entry": 0.05, "arm_throw": 0.08, "twist": 1.0}),
                  MappingProxyType({"delta": -0.12, "knee": 1.0})),
        }),
    }),
})  # fmt: skip


def _twist_preset(
    position: str, direction: str, body: str, twist: float
) -> tuple[Mapping[str, float], Mapping[str, float], Mapping[str, float]]:
    """The :data:`TWIST_SOMERSAULT_PRESETS` entry, or a :class:`ConfigError` saying why the
    combination is not built."""
    if not math.isfinite(twist):
        raise ConfigError(f"twist must be a finite number of turns, got {twist!r}")
    preset = TWIST_SOMERSAULT_PRESETS.get(body, {}).get(f"{direction}/{position}", {}).get(twist)
    if preset is None:
        raise ConfigError(
            f"a twisting somersault is built only as the male back layout with one twist "
            f"(--position layout --direction backward --twist 1), got body {body!r}, direction "
            f"{direction!r}, position {position!r}, twist {twist!r} (thesis 5.2): a half twist "
            "cannot be stopped (the arms' undo runs into the shoulders' cones), a twist thrown "
            "in the tuck or pike did not stop, and no other body or direction is tuned "
            "(docs/athletics.md)"
        )
    return preset


def somersault_maneuver(
    position: str = "tuck", direction: str = "backward", body: str = "male",
    backpack: float = 0.0, twist: float = 0.0,
) -> Maneuver:  # fmt: skip
    """The standing somersault (thesis 8.4-8.5) as a maneuver: balance, leap with rotation,
    tumble in ``position``, land, balance. Uses the male preset for a body or direction that
    has none of its own; such runs are untuned and their reports say what happened. ``twist``
    (turns) uses :data:`TWIST_SOMERSAULT_PRESETS`; a combination with no entry there is
    refused (:class:`ConfigError`, with the reason)."""
    if direction not in DIRECTIONS:
        raise UnknownKeyError(
            f"unknown somersault direction {direction!r}; valid directions are {list(DIRECTIONS)}"
        )
    if position not in POSITIONS:
        raise UnknownKeyError(
            f"unknown somersault position {position!r}; valid positions are {sorted(POSITIONS)}"
        )
    leap: Mapping[str, float | str]
    land: Mapping[str, float | list[float]]
    if twist:
        leap, tumble, land = _twist_preset(position, direction, body, twist)
        start = TIMED_START
    else:
        owner = body if direction in SOMERSAULT_PRESETS.get(body, {}) else "male"
        presets = SOMERSAULT_PRESETS[owner]
        key = f"{direction}/{position}" if f"{direction}/{position}" in presets else direction
        leap, tumble, land = presets[key]
        start = PRESET_STARTS.get(f"{owner}/{key}", SETTLED_START)
    phases = (
        start,
        Phase("leap", "liftoff", dict(leap)),
        Phase("tumble", "open", {"position": position, **tumble}),
        Phase("land", "settled", dict(land)),
        # stand up slowly out of the landing's deep crouch: a quicker stand-up (0.5 s) carried
        # the COM forward off the feet after most perturbed landings (docs/athletics.md)
        Phase("balance", "never", {"settle": 2.0}),
    )
    name = f"{direction}_somersault_{position}" + (f"_twist{twist:g}" if twist else "")
    return Maneuver(name, phases, body, SOMERSAULT_SECONDS[start.exit], backpack)


def somersault(
    position: str = "tuck",
    direction: str = "backward",
    body: str = "male",
    *,
    twist: float = 0.0,
    backpack: float = 0.0,
    on_tick: Callable[[float], None] | None = None,
    fps: float = 60.0,
    contact: str = DEFAULT_CONTACT,
) -> AthleticsResult:
    """A standing somersault (:func:`somersault_maneuver`; ``contact``: the athletics contact
    model, :data:`~reactmocap.athletics.scene.CONTACT_MODELS`). ``twist`` (turns) is built only
    where :data:`TWIST_SOMERSAULT_PRESETS` has an entry (the male back layout with one twist);
    anything else is refused with the reason. With a twist the report adds
    ``twist_error_deg`` (``|twist_deg|`` against the commanded turns) and ``twist_stopped``
    (the throw undone before touchdown)."""
    if not (math.isfinite(backpack) and backpack >= 0):
        raise ConfigError(f"backpack must be >= 0 kg, got {backpack!r}")
    m = somersault_maneuver(position, direction, body, backpack, twist)
    result = run_maneuver(m, on_tick=on_tick, fps=fps, contact=contact)
    rep = result.report
    rep.update(position=position, direction=direction, twist_turns=twist)
    if twist:
        undone, td = rep.get("twist_undone_s"), rep.get("touchdown_s")
        rep["twist_error_deg"] = abs(rep["twist_deg"]) - 360.0 * twist
        rep["twist_stopped"] = undone is not None and td is not None and undone < td
    return result


# ---------------------------------------------------------------------------------- dives
#: the dive's tumble lead (rad) per position, tuned by hand on the male body (5 m, 1.5 turns);
#: the pike's 1.6 since its hips are at DIVE_PIKE_HIP (2.0 before: the shallower pike turns
#: slower, and the nominal entered 24 deg short of vertical; at 1.6, 3 deg)
DIVE_LEADS: Mapping[str, float] = MappingProxyType({"pike": 1.6, "tuck": 1.7, "layout": 0.0})
DIVE_DIRECTIONS = ("backward",)
#: the pike dive's hip flexion (rad; the pike's own is -2.2): at -2.2 the somersault axis is
#: the piked body's intermediate principal axis (an unstable turn); at -2.0 it is the largest
#: by 0.28 kg m^2 only (male), and a take-off's few kg m^2/s of yaw or cartwheel still tilted
#: the body out of the plane; at -1.9 by 0.59 (TumbleParams.hip; docs/athletics.md)
DIVE_PIKE_HIP = -1.9
#: the twists a dive is built for (turns)
DIVE_TWISTS = (0.5, 1.0)
#: the twisting dive (thesis 5.2's tilt twist), tuned by hand on the male body from 5 m: a
#: back dive in layout (half a somersault, head first), the leap aiming at less spin (-45 kg
#: m^2/s; at the back somersault's -55 the entry over-rotated to 49 degrees), the arms thrown
#: 2.0 rad right after lift-off (entry 0.1 s) for the fastest twist; the tumble stays in layout
#: until the twist is stopped. Tried and not kept: the twist in the 1.5-somersault pike (the
#: pike's pelvis-to-head line is not its long axis: the tilt and the twist do not stop when the
#: arms come back, and the somersault lost 110 degrees: entry 125 degrees off)
TWIST_DIVE: tuple[Mapping[str, float], Mapping[str, float]] = (
    MappingProxyType({"spin": -45.0}),
    MappingProxyType({"arm_tilt": 2.0, "entry": 0.1}),
)


def dive_maneuver(
    position: str = "pike", direction: str = "backward", body: str = "male",
    height: float = 5.0, turns: float = 1.5, twist: float = 0.0,
) -> Maneuver:  # fmt: skip
    """A backward dive of ``turns`` somersaults (1.5: head first) in ``position`` from a
    ``height`` m platform: balance, the back somersault's leap, tumble (aimed at the water),
    stretch. The tumble's opening predicts with the stretched body's inertia. ``twist``
    (turns, one of :data:`DIVE_TWISTS`) adds :data:`TWIST_DIVE`'s tilt twist, stopped at that
    many turns; it is built for the layout back dive (``position`` layout, ``turns`` 0.5)."""
    if direction not in DIVE_DIRECTIONS:
        raise UnknownKeyError(
            f"unknown dive direction {direction!r}; built: {list(DIVE_DIRECTIONS)}"
        )
    if position not in POSITIONS:
        raise UnknownKeyError(
            f"unknown dive position {position!r}; valid positions are {sorted(POSITIONS)}"
        )
    if not (math.isfinite(height) and 1.0 <= height <= PLATFORM_MAX):
        raise ConfigError(f"dive platform height must be 1-{PLATFORM_MAX:g} m, got {height!r}")
    if not (math.isfinite(turns) and turns > 0):
        raise ConfigError(f"dive turns must be > 0, got {turns!r}")
    _check_twist(twist)
    if twist and (position != "layout" or turns != 0.5):
        raise ConfigError(
            "a twisting dive is built as the layout back dive (position layout, turns 0.5), "
            f"got position {position!r}, turns {turns!r} (docs/athletics.md)"
        )
    leap = dict(SOMERSAULT_PRESETS["male"]["backward"][0])
    i_open = round(somersault_inertia(athlete(body), stretch_angles()), 2)
    tumble = {"position": position, "turns": turns, "lead": DIVE_LEADS[position],
              "target_height": -height, "open_inertia": i_open, "latest": 0.3,
              "max_seconds": 5.0}  # fmt: skip
    if position == "pike":
        tumble["hip"] = DIVE_PIKE_HIP
    if twist:
        leap.update(TWIST_DIVE[0])
        tumble.update(TWIST_DIVE[1], twist=twist)
    phases = (
        TIMED_START,
        Phase("leap", "liftoff", leap),
        Phase("tumble", "open", tumble),
        Phase("stretch", "never", {}),
    )
    seconds = round(1.7 + math.sqrt(2.0 * (height + 2.0) / 9.81), 1)
    name = f"dive_{direction}_{position}" + (f"_twist{twist:g}" if twist else "")
    return Maneuver(name, phases, body, seconds, 0.0, height)


def _check_twist(twist: float) -> None:
    if not math.isfinite(twist) or (twist and twist not in DIVE_TWISTS):
        raise ConfigError(
            f"dive twist must be 0 or one of {list(DIVE_TWISTS)} turns, got {twist!r}"
        )


def dive(
    position: str | None = None,
    direction: str = "backward",
    body: str = "male",
    *,
    height: float = 5.0,
    turns: float | None = None,
    twist: float = 0.0,
    on_tick: Callable[[float], None] | None = None,
    fps: float = 60.0,
) -> AthleticsResult:
    """A platform dive (:func:`dive_maneuver`). ``landed`` is a clean entry (head first within
    ``dive.ENTRY_TOLERANCE`` of straight down when the COM reaches the water), ``fell`` its
    opposite. ``position`` and ``turns`` default to the pike 1.5 somersaults, or with a
    ``twist`` (turns, :data:`DIVE_TWISTS`) to the layout back dive (half a somersault) that
    the twist is built for; the report adds ``twist_turns`` (commanded), ``twist_error_deg``
    (``|twist_deg|`` against it) and ``twist_stopped`` (the throw undone before the entry)."""
    _check_twist(twist)
    position = position or ("layout" if twist else "pike")
    turns = turns if turns is not None else (0.5 if twist else 1.5)
    result = run_maneuver(dive_maneuver(position, direction, body, height, turns, twist),
                          on_tick=on_tick, fps=fps)  # fmt: skip
    rep = result.report
    rep.update(position=position, direction=direction, turns=turns, twist_turns=twist)
    if twist:
        undone, entry = rep.get("twist_undone_s"), rep.get("entry_s")
        rep["twist_error_deg"] = abs(rep["twist_deg"]) - 360.0 * twist
        rep["twist_stopped"] = undone is not None and entry is not None and undone < entry
    return result


# ---------------------------------------------------------------------------------- handspring
#: the back handspring (thesis 8.3), tuned by hand on the male body: a leap aiming at a large
#: backward angular momentum (the hands must reach the floor with the body about inverted),
#: the hand support (arched, arms over the head; on contact the shoulders close and the hips
#: and trunk snap down), the landing and a slow stand-up (docs/athletics.md)
HANDSPRING_PRESET: Mapping[str, Mapping[str, float]] = MappingProxyType({
    "leap": MappingProxyType({"effort": 0.6, "spin": -110.0, "spin_limit": 1.5,
                              "com_offset": -0.1}),
    "handspring": MappingProxyType({"give": 0.5, "push_after": 0.06, "push": -2.65,
                                    "snap_hips": -1.2, "snap_trunk": 0.5, "snap_knees": 0.6,
                                    "snap": 0.1}),
    "land": MappingProxyType({"delta": -0.45}),
})  # fmt: skip
#: a body's own replacements for the male preset's leap, landing and last balance
#: parameters. The female (hand-tuned 2026-12-02, narrow: docs/athletics.md) leaps harder
#: with more hip feedback, and lands on feet placed farther behind her (the hip swing
#: allowed past asin 0.9) with stiffer, more damped knees, which stop the legs bouncing her
#: back into the air; since 2026-12-05 her crouch's COM target is eased back over 0.2 s
#: (``com_ramp``, as the male's; the step spread her take-off momentum and 10/50 starts at a
#: tenth missed the hands) with the hips' feedback allowed 1.8 rad and her feet 56 cm back;
#: since 2026-12-05 (later) that delta is scaled by the spin the push left (``spin_ref``, her
#: nominal's -41.0 kg m^2/s: a start whose hands met the floor less turned keeps less spin
#: and lands only with its feet nearer)
HANDSPRING_BODY_PRESET: Mapping[str, Mapping[str, Mapping[str, Any]]] = MappingProxyType({
    # the male's landing scales its delta by the spin the push left (LandingParams.spin_ref:
    # the spin at the nominal's release, 2026-12-03). Since 2026-12-03 his knees aim the
    # hands' contact at -196 deg (HandspringParams.aim) about a 0.4 rad bend, on a leap that
    # falls a little short for it (spin_limit 1.3: -76 kg m^2/s), and his feet land farther
    # back; since 2026-12-03 (later) the landing steps once the capture point lies 5 cm past
    # the feet (LandingParams.step: 11/50 and 17/50 perturbed starts on seeds 0 and 1, from
    # 10 and 15, held-out seed 2 15 from 13; docs/athletics.md). Since 2026-12-04 his crouch's
    # COM target goes 13 cm back over 0.2 s (LeapParams.com_ramp; the 10 cm step hopped every
    # start off the floor) and his feet land 60 cm back (18/50 and 23/50 on seeds 0 and 1,
    # from 17 and 20); since 2026-12-04 (later) the knees' aim is centred on that crouch's
    # nominal (-186 deg, 0.9 rad, up to 1.3: about 0.4 rad the knees sat at their clip); since
    # 2026-12-05 the push stops at a 1.0 m apex looked 12 ms ahead (LeapParams.rise_lead: only
    # the over-leaps are cut; 27/50 and 27/50 from 24 and 24), and (later) the hips' spin
    # allowance opens to 1.6 rad a tick before that cut (LeapParams.rise_spin_rate: 29/50 and
    # 26/50 from 27 and 27); since 2026-12-05 (later) the landing's step swings to the
    # capture point itself (reach 0) and the recovery stands up to 0.8 of the straight leg
    # (LandingParams.recover_leg: 32/50 and 26/50 from 29 and 26, held-out seed 2 30 from
    # 27); and (later) his last balance keeps the COM target's sideways part between both
    # soles while one is unloaded (Posture.side_both: 35/50 and 29/50 from 32 and 26, held-out
    # seed 2 30 from 30); and (later) his landing's step also fires on the capture point
    # across the feet carried 0.25 s on (LandingParams.step_foresee with step_across: 40/50
    # and 31/50 from 35 and 29, held-out seed 2 35 from 30); and (latest) at each step's
    # touchdown both knees' targets go to their mean (LandingParams.step_knees: 40/50 and
    # 36/50 from 40 and 31, held-out seed 2 38 from 35); and (last) a foot left hanging 0.4 s
    # with no swing is put down (LandingParams.step_hang_plant: 41/50 and 37/50 from 40 and
    # 36, held-out seed 2 39/50 from 38); since 2026-12-06 the absorb's hand-over held while
    # he still turns back (LandingParams.absorb_spin) and after such a hold no COM-servo hip
    # offset (held_hip_share 0: 44 / 40 / 42 of 50 on seeds 0-2 from 42 / 39 / 40). A list:
    # a maneuver file's numbers load as one
    "male": MappingProxyType({
        "leap": MappingProxyType({"spin_limit": 1.3, "hold": 0.22, "com_offset": -0.13,
                                  "com_ramp": 0.2, "rise_cap": 1.0, "rise_lead": 0.012,
                                  "rise_spin_limit": 1.6, "rise_spin_rate": 33.5}),
        "handspring": MappingProxyType({"aim": -3.25, "knees": 0.9, "aim_knees": 1.3}),
        "land": MappingProxyType({"delta": -0.6, "spin_ref": -96.8,
                                  "step": [0.05, 0.0, 0.3, 0.25], "recover_leg": 0.8,
                                  "step_across": 0.05, "step_foresee": 0.25,
                                  "step_knees": 1.0, "step_hang_plant": 0.4,
                                  "absorb_spin": [-15.0, 0.5], "held_hip_share": 0.0}),
        "balance": MappingProxyType({"side_both": True}),
    }),
    "female": MappingProxyType({
        "leap": MappingProxyType({"effort": 0.75, "spin": -70.0, "spin_limit": 1.8,
                                  "com_ramp": 0.2}),
        # hop_spin since 2026-12-06: the recovery's hop placed for the spin it left with
        "land": MappingProxyType({"delta": -0.56, "spin_ref": -41.0, "swing_cap": 0.97,
                                  "knee_stiffness": 1.0, "damping": 2.0,
                                  "hop_spin": [-5.5, 0.02]}),
    }),
})  # fmt: skip


#: seconds a body's handspring is simulated from :data:`TIMED_START` (others 5.0; from
#: :data:`SETTLED_START` :data:`SETTLE_SECONDS` more): the male's aimed contact touches down
#: later and stands up ~0.4 s later (2026-12-03)
HANDSPRING_SECONDS: Mapping[str, float] = MappingProxyType({"male": 5.5})
#: a body's handspring start (others :data:`TIMED_START`): since 2026-12-03 the male settles
#: first (:data:`SETTLED_START`)
#: and holds his crouch 0.22 s (the leap's ``hold``; at 0.15 the nominal, settled at 0.23 s,
#: fell back): perturbed starts crouched on one foot and left the leap turning about the
#: vertical (docs/athletics.md)
HANDSPRING_STARTS: Mapping[str, Phase] = MappingProxyType({"male": SETTLED_START})


def handspring_maneuver(body: str = "male") -> Maneuver:
    """The back handspring as a maneuver: balance, leap with backward rotation, hand support
    (:class:`~reactmocap.athletics.handspring.Handspring`), land, balance. A body with a
    :data:`HANDSPRING_BODY_PRESET` entry gets its own leap, landing and last balance; any
    other body than the male one aims its leap at the male's angular momentum scaled by its
    layout inertia (the same spin rate); that is untuned and its report says what happened."""
    leap = dict(HANDSPRING_PRESET["leap"])
    hands = dict(HANDSPRING_PRESET["handspring"])
    land: dict[str, Any] = dict(HANDSPRING_PRESET["land"])
    last: dict[str, Any] = {"settle": 2.0}
    own = HANDSPRING_BODY_PRESET.get(body)
    if own is not None:
        leap.update(own.get("leap", {}))
        hands.update(own.get("handspring", {}))
        land.update(own.get("land", {}))
        last.update(own.get("balance", {}))
    elif body != "male":
        ratio = somersault_inertia(athlete(body), "layout") / somersault_inertia(
            athlete("male"), "layout"
        )
        leap["spin"] = round(leap["spin"] * ratio, 1)
    start = HANDSPRING_STARTS.get(body, TIMED_START)
    seconds = HANDSPRING_SECONDS.get(body, 5.0) + (
        SETTLE_SECONDS if start is SETTLED_START else 0.0
    )
    phases = (
        start,
        Phase("leap", "liftoff", leap),
        Phase("handspring", "released", hands),
        Phase("land", "settled", land),
        Phase("balance", "never", last),
    )
    return Maneuver("back_handspring", phases, body, seconds)


def handspring(
    body: str = "male",
    *,
    on_tick: Callable[[float], None] | None = None,
    fps: float = 60.0,
    contact: str = DEFAULT_CONTACT,
) -> AthleticsResult:
    """A standing back handspring (:func:`handspring_maneuver`; ``contact`` as
    :func:`somersault`). The report adds
    ``hands_contact_s`` (time the hands were on the floor), the hands' first and last contact
    and the push's time; ``fell`` ignores the hands' own contacts
    (:func:`~reactmocap.athletics.handspring.handspring_report`)."""
    return run_maneuver(handspring_maneuver(body), on_tick=on_tick, fps=fps, contact=contact)

"""Athletic controllers on the simulation engine (thesis: Wooten; issue "Athletics I"): the
thesis's bodies, parameterised basis controllers for balancing, leaping and landing built on
the engine's state machines, a sequencer that chains them, and a registry of behaviours
(:func:`run`); tumbling and composed maneuvers (issue "Athletics II": :func:`somersault`,
:func:`dive`, maneuver files with :func:`load_maneuver` / :func:`run_maneuver`). Design and
measurements: ``docs/athletics.md``."""

from reactmocap.athletics.balance import Balance, BalanceGains, BalanceLaw, Posture
from reactmocap.athletics.behaviours import BEHAVIOURS, AthleticsResult, Behaviour, Param, run
from reactmocap.athletics.bodies import BODIES, Athlete, athlete, thesis_character, thesis_skeleton
from reactmocap.athletics.land import Landing, LandingParams
from reactmocap.athletics.leap import Leap, LeapParams
from reactmocap.athletics.machine import NEXT, Basis, Context, angle, apex, liftoff, touchdown
from reactmocap.athletics.maneuvers import Maneuver, Phase, load_maneuver, run_maneuver
from reactmocap.athletics.routines import dive, somersault
from reactmocap.athletics.sequencer import Sequencer
from reactmocap.athletics.tumble import Tumble, TumbleParams

__all__ = [
    "BEHAVIOURS",
    "BODIES",
    "NEXT",
    "Athlete",
    "AthleticsResult",
    "Balance",
    "BalanceGains",
    "BalanceLaw",
    "Basis",
    "Behaviour",
    "Context",
    "Landing",
    "LandingParams",
    "Leap",
    "LeapParams",
    "Maneuver",
    "Phase",
    "Param",
    "Posture",
    "Sequencer",
    "Tumble",
    "TumbleParams",
    "angle",
    "apex",
    "athlete",
    "dive",
    "liftoff",
    "load_maneuver",
    "run",
    "run_maneuver",
    "somersault",
    "thesis_character",
    "thesis_skeleton",
    "touchdown",
]

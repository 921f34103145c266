"""Controllers: the interface the engine ticks, the state-machine base, the registry with the
one table of defaults, and the tracking controllers (PD, balance, whole-body, predictive,
root assist)."""

from reactmocap.sim.controllers.balance import StanceBalance
from reactmocap.sim.controllers.base import (
    Controller,
    FunctionController,
    GainScalable,
    Group,
    Holdable,
    Scheduled,
    check_character,
    check_params,
)
from reactmocap.sim.controllers.machine import (
    Event,
    State,
    StateMachine,
    Transition,
    after,
    when,
)
from reactmocap.sim.controllers.pd import Passive, PDTracker
from reactmocap.sim.controllers.predictive import PredictiveTracker
from reactmocap.sim.controllers.registry import (
    CONTROLLERS,
    ControllerSpec,
    build,
    controller_help,
    controller_spec,
    register,
)
from reactmocap.sim.controllers.root_assist import RootAssist
from reactmocap.sim.controllers.wholebody import WholeBodyPlan, WholeBodyTracker

__all__ = [
    "CONTROLLERS",
    "Controller",
    "ControllerSpec",
    "Event",
    "FunctionController",
    "GainScalable",
    "Group",
    "Holdable",
    "PDTracker",
    "Passive",
    "PredictiveTracker",
    "RootAssist",
    "Scheduled",
    "StanceBalance",
    "State",
    "StateMachine",
    "Transition",
    "WholeBodyPlan",
    "WholeBodyTracker",
    "after",
    "build",
    "check_character",
    "check_params",
    "controller_help",
    "controller_spec",
    "register",
    "when",
]

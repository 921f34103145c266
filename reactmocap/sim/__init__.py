"""Physics simulation on MuJoCo: the character built from a skeleton, the world, the
inertia-scaled PD servo, balance and whole-body tracking controllers, impacts and contacts,
rollouts, and Motion <-> state conversion."""

from reactmocap.sim.balance import StanceBalance
from reactmocap.sim.character import (
    BALL_JOINTS,
    BODY_ALIASES,
    SIM_BODIES,
    Character,
    build_character,
)
from reactmocap.sim.feasibility import SupportFeasibility, support_feasibility
from reactmocap.sim.impacts import (
    CharacterContact,
    ContactReport,
    Impact,
    ImpactSchedule,
    KinematicContact,
    contact_report,
    first_contact,
)
from reactmocap.sim.pd import PDServo, critical_kv
from reactmocap.sim.predictive import PredictiveTracker
from reactmocap.sim.retarget import Retargeter, retarget
from reactmocap.sim.rollout import (
    TRACKING_CONTROLLERS,
    MotionTracker,
    RolloutResult,
    RootAssist,
    TrackingController,
    TrackReport,
    push_clip,
    rollout,
    track_clip,
    tracking_controller,
)
from reactmocap.sim.wholebody import (
    ReferencePath,
    WholeBodyPlan,
    WholeBodyTracker,
    reference_path,
)
from reactmocap.sim.world import PREFIXES, World, WorldCharacter, WorldConfig

__all__ = [
    "BALL_JOINTS",
    "BODY_ALIASES",
    "PREFIXES",
    "SIM_BODIES",
    "TRACKING_CONTROLLERS",
    "Character",
    "CharacterContact",
    "ContactReport",
    "Impact",
    "ImpactSchedule",
    "KinematicContact",
    "MotionTracker",
    "PDServo",
    "PredictiveTracker",
    "ReferencePath",
    "RolloutResult",
    "Retargeter",
    "RootAssist",
    "StanceBalance",
    "SupportFeasibility",
    "TrackReport",
    "TrackingController",
    "World",
    "WorldCharacter",
    "WholeBodyPlan",
    "WholeBodyTracker",
    "WorldConfig",
    "build_character",
    "contact_report",
    "critical_kv",
    "first_contact",
    "push_clip",
    "reference_path",
    "retarget",
    "rollout",
    "support_feasibility",
    "track_clip",
    "tracking_controller",
]

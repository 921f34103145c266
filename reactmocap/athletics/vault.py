"""The handspring vault (Hodgins et al. 1995, "Vaulting and Balancing"): a gymnast runs onto a
springboard, springs onto a vaulting horse with her hands, turns a somersault over it and
lands on the far side. Six states: hurdle step (the flight before the board), board contact
(the board springs; at its deepest the knees extend and add energy), first flight (the
shoulders aim the hands at the horse, eq. 12), horse contact (arms straight, no shoulder or
wrist torque; or, unlike the paper, with ``VaultParams.arm_spring`` the arms a spring that
yields and then blocks), second flight (layout off the horse, then the athletics tumbling controller
tucks to turn faster and opens when the rotation it predicts at touchdown is one somersault)
and landing (the athletics landing and balance controllers). The body is the thesis female
scaled to the mean gymnast of Table 1 (47.96 kg, 1.55 m); the board is a plate on a spring
and damper; the horse is of the women's competition height of Takei's data (1.20 m).

:func:`vault` runs one vault and reports it; the pieces live in ``vault_setup`` (apparatus,
body, :class:`VaultParams`), ``vault_control`` (the :class:`Vault` states) and
``vault_table1`` (:data:`TABLE1`, :func:`table1`), all importable from here. Design and
figures: ``docs/athletics.md``."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.balance import Balance, Posture
from reactmocap.athletics.bodies import Athlete, athlete
from reactmocap.athletics.land import Landing, LandingParams
from reactmocap.athletics.machine import Context
from reactmocap.athletics.report import report_json
from reactmocap.athletics.sequencer import Sequencer
from reactmocap.athletics.tumble import Tumble, TumbleParams
from reactmocap.athletics.vault_control import Vault, VaultLog, VaultLogger
from reactmocap.athletics.vault_setup import (
    ALL_ROWS_VALUES,
    BOARD,
    HORSE,
    Apparatus,
    VaultParams,
    vault_athlete,
    vault_start,
    vault_world,
)
from reactmocap.athletics.vault_table1 import (
    GYMNAST_HEIGHT,
    GYMNAST_MASS,
    TABLE1,
    TABLE1_KEYS,
    Table1Row,
    table1,
)
from reactmocap.errors import ConfigError
from reactmocap.library.motion import Motion
from reactmocap.sim.bodies import BALL_JOINTS
from reactmocap.sim.rollout import RolloutResult, rollout
from reactmocap.sim.world import World

NJ = len(BALL_JOINTS)

__all__ = [
    "ALL_ROWS_VALUES",
    "BOARD",
    "GYMNAST_HEIGHT",
    "GYMNAST_MASS",
    "HORSE",
    "TABLE1",
    "TABLE1_KEYS",
    "Apparatus",
    "Table1Row",
    "VaultParams",
    "VaultResult",
    "table1",
    "vault",
    "render_world_video",
    "vault_athlete",
    "vault_plot",
    "vault_start",
    "vault_world",
]


# ---------------------------------------------------------------------------------- a vault
@dataclass
class VaultResult:
    motion: Motion
    report: dict[str, Any]
    rollout: RolloutResult
    log: dict[str, NDArray]
    transitions: list[tuple[float, str, str]]
    world: World
    params: VaultParams

    def report_json(self) -> str:
        return report_json(self.report)

    def scene_video(self, path: str | Path, fps: float = 30.0) -> Path:
        """The vault as recorded, rendered with the board and horse (MuJoCo)."""
        return render_world_video(self.rollout, path, fps=fps)


def render_world_video(res: RolloutResult, path: str | Path, fps: float = 30.0,
                       size: tuple[int, int] = (512, 384)) -> Path:  # fmt: skip
    """A rollout's recorded states rendered in its own world (its apparatus included), the
    camera following character 0 from the side. Raises RenderUnavailable without GL."""

    from reactmocap.response.plots import write_video
    from reactmocap.response.render import free_camera, offscreen_renderer

    world = res.world
    m = world.model
    d = mujoco.MjData(m)
    _times, qpos = res.frames()
    step = max(1, round(res.fps[0] / fps))
    qpos = qpos[::step]
    width, height = size
    renderer = offscreen_renderer(m, size)
    cam = free_camera(5.0, -10.0, 90.0)
    frames = np.empty((len(qpos), height, width, 3), dtype=np.uint8)
    root = world.characters[0].qpos_adr
    try:
        for i, q in enumerate(qpos):
            d.qpos[:] = q
            mujoco.mj_kinematics(m, d)
            cam.lookat[:] = (q[root], q[root + 1], 1.0)
            renderer.update_scene(d, camera=cam)
            frames[i] = renderer.render()
    finally:
        renderer.close()
    return Path(write_video(frames, path, fps))


#: seconds the gymnast must stay up after landing for ``landed`` (and to the end of the run)
LANDED_AFTER = 1.0
#: at the end of the run (its last 0.1 s) the COM must be within this horizontal distance
#: (m) of the feet's support centre and slower than this (m/s) for ``landed``
SETTLED_OFFSET = 0.15
SETTLED_SPEED = 0.3
#: seconds simulated by default: the vault takes about 1.1 s to the floor, then 3 s standing
DEFAULT_SECONDS = 4.2
#: seconds both feet may be off the floor after touchdown (a bounce) before she is down
BOUNCE_S = 0.15
#: physics steps per control tick (4 ms; the board contact lasts about 0.14 s)
CONTROL_EVERY = 8


def vault(
    *,
    body: str = "female",
    params: VaultParams | None = None,
    seconds: float | None = None,
    fps: float = 60.0,
    on_tick: Callable[[float], None] | None = None,
) -> VaultResult:
    """Simulate the handspring vault and measure Table 1 on it (:func:`table1`). ``body`` is
    ``"female"`` (the thesis female scaled to Table 1's mean gymnast) or ``"male"`` (the
    thesis male as is)."""
    p = params or VaultParams()
    if body == "female":
        ath = vault_athlete()
    elif body == "male":
        ath = athlete("male")
    else:
        raise ConfigError(f"unknown vault body {body!r}; valid bodies are ['female', 'male']")
    if seconds is not None and not (math.isfinite(seconds) and seconds > 0):
        raise ConfigError(f"seconds must be > 0, got {seconds!r}")
    duration = DEFAULT_SECONDS if seconds is None else float(seconds)
    world = vault_world(ath, p)
    q, v = vault_start(ath, p)
    world.set_pose(0, q, v)
    ctx = Context.make(world, ath, control_every=CONTROL_EVERY)
    log = VaultLog()
    basis = Vault(p, log)
    # the COM's standing height: the tumbling controller's touchdown height is a fraction of it
    ctx.standing_com = float(ath.com_of(ath.standing_qpos(np.zeros((NJ, 3))))[2])
    tumble = Tumble(TumbleParams(position=p.position2, turns=p.turns2,
                                 touchdown_height=p.touchdown_com))  # fmt: skip
    stand = Balance(Posture(leg=p.stand_leg, settle=p.stand_settle))
    landing = LandingParams(
        knee=p.land_knee,
        lead=p.land_lead,
        delta=p.land_delta,
        damping=p.land_damping,
        knee_stiffness=p.land_knee_stiffness,
        restore=p.land_restore,
        lean=p.land_lean,
    )
    seq = Sequencer(ctx, [basis, tumble, Landing(landing), stand])
    logger = VaultLogger(basis, seq)
    tick = None if on_tick is None else (lambda t: on_tick(min(t / duration, 1.0)))
    try:
        res = rollout(world, duration, controllers=[seq, logger], record_fps=fps,
                      on_unstable="stop", on_tick=tick, tick_every=400)  # fmt: skip
    finally:
        ctx.rig.release()
    arrays = log.arrays()
    trans = [(tr.time, tr.source, tr.target) for tr in seq.transitions]
    report = _report(ath, p, arrays, trans, res, ctx)
    motion = res.motion(0, name=f"vault_{ath.name}")
    return VaultResult(motion, report, res, arrays, trans, world, p)


def _report(ath: Athlete, p: VaultParams, log: dict[str, NDArray],
            trans: list[tuple[float, str, str]], res: RolloutResult, ctx: Context) -> dict[str, Any]:  # fmt: skip
    height = GYMNAST_HEIGHT if ath.name == "female" else 1.84
    rows = table1(log, trans, ath.mass, height)
    inside = {}
    close = {}
    for r in TABLE1:
        v = rows[r.key]
        inside[r.key] = v is not None and r.low <= v <= r.high
        if r.unit == "m/s":
            close[r.key] = v is not None and abs(v - r.mean) <= 0.1 * abs(r.mean)
    clear = log["over_horse_clearance"]
    finite = clear[np.isfinite(clear)]
    cleared = bool(
        rows["horse_contact_s"] is not None and (finite.size == 0 or finite.min() > -0.01)
    )
    # Table 1 counts the forearms' contacts too; a handspring's support is the hands'
    on_horse = log["on_horse"].astype(bool)
    forearm_share = (
        float(log["forearm_on_horse"][on_horse].astype(bool).mean()) if on_horse.any() else 0.0
    )
    pitch = np.unwrap(log["pitch"]) if log["pitch"].size else np.zeros(0)
    rotation = float(np.degrees(pitch[-1] - pitch[0])) if pitch.size else 0.0
    td_i = int(np.flatnonzero(log["on_floor"].astype(bool))[0]) if log["on_floor"].any() else -1
    # no touchdown in the run (cut short): no rotation at it, not the last frame's
    rotation_td = float(np.degrees(pitch[td_i] - pitch[0])) if pitch.size and td_i >= 0 else None
    t = log["t"]
    floor = log["on_floor"].astype(bool)
    td = float(t[np.flatnonzero(floor)[0]]) if floor.any() else None
    arr = ctx.log.arrays()
    pelvis = arr["pelvis"]
    others = arr["others"]
    at = arr["t"]
    standing = float(ath.standing_qpos(np.zeros((NJ, 3)))[2])
    # after touchdown she is down once anything but the feet touches the floor, the pelvis
    # sinks below 45% of its standing height, or both feet have been off the floor for
    # longer than BOUNCE_S (a landing that springs her back into the air is no landing)
    after_td = at >= (td if td is not None else np.inf)
    feet_first = td is not None and not others[at <= td + 0.02].any()
    last_foot = np.maximum.accumulate(np.where(after_td & (arr["feet"] > 0), at, td or 0.0))
    down = after_td & (others | (pelvis <= 0.45 * standing) | (at - last_foot > BOUNCE_S))
    up_s = 0.0
    if td is not None and feet_first:
        up_s = float(at[np.flatnonzero(down)[0]]) - td if down.any() else res.seconds - td
    # and at the end she stands balanced: the COM over her feet and still (a fall that has
    # not yet reached the floor when the run stops is no landing)
    end = at >= at[-1] - 0.1 if at.size else at.astype(bool)
    settled = bool(end.any() and (arr["offset"][end] < SETTLED_OFFSET).all()
                   and (np.hypot(*arr["com_vel"][end, :2].T) < SETTLED_SPEED).all())  # fmt: skip
    landed = bool(feet_first and not down.any() and settled
                  and res.seconds >= (td or 0) + LANDED_AFTER - 1e-6)  # fmt: skip
    report: dict[str, Any] = {
        "behaviour": "vault", "body": ath.name, "mass_kg": round(ath.mass, 2),
        "table1": rows,
        "table1_inside": int(sum(inside.values())),
        "table1_outside": [k for k, ok in inside.items() if not ok],
        "velocities_within_10pct": int(sum(close.values())),
        "cleared": cleared,
        "min_clearance_over_horse_m": float(finite.min()) if finite.size else None,
        "horse_forearm_share": forearm_share,
        "landed": landed,
        "touchdown_s": td,
        "up_after_touchdown_s": up_s,
        "settled_at_end": settled,
        "rotation_deg": rotation,
        "rotation_at_touchdown_deg": rotation_td,
        "board_stiffness_n_m": p.board_stiffness,
        "board_damping_n_s_m": p.board_damping,
        "horse_height_m": HORSE.top,
        "states": [[round(a, 3), b, c] for a, b, c in trans],
        "simulated_s": round(res.seconds, 3), "wall_s": round(res.wall_s, 3),
        "realtime_factor": round(res.seconds / max(res.wall_s, 1e-9), 2), "status": res.status,
    }  # fmt: skip
    if res.status != "ok":
        report["reason"] = res.reason
    notes = []
    if not cleared:
        notes.append("the gymnast did not clear the horse (a body below its top while over it)")
    if not landed:
        notes.append(
            "the gymnast did not land on her feet and stay up (feet down, nothing "
            "else touching) for 1 s and to the end of the run, standing still over her feet "
            "at the end"
        )
    if report["table1_inside"] < len(TABLE1):
        notes.append(f"Table 1 rows outside the human range: {report['table1_outside']}")
    report["notes"] = notes
    return report


def vault_plot(result: VaultResult, path: str | Path) -> Path:
    """COM path with the apparatus, and Table 1: ours against the human range and mean."""
    from reactmocap.io import save_png
    from reactmocap.response.plots import pyplot

    plt = pyplot()
    log = result.log
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 4.5), dpi=100)
    a1.plot(log["com"][:, 0], log["com"][:, 2], "k-", lw=1.2, label="COM")
    b = BOARD
    a1.add_patch(plt.Rectangle((b.centre[0] - b.size[0] / 2, 0), b.size[0], b.top,
                               color="tan", alpha=0.6))  # fmt: skip
    hx = result.params.horse_distance
    a1.add_patch(plt.Rectangle((hx - HORSE.size[0] / 2, 0), HORSE.size[0], HORSE.top,
                               color="saddlebrown", alpha=0.6))  # fmt: skip
    a1.set_aspect("equal", adjustable="datalim")
    a1.set_xlabel("x (m)")
    a1.set_ylabel("z (m)")
    a1.set_title("handspring vault: COM path")
    rows = result.report["table1"]
    for i, r in enumerate(TABLE1):
        lo, hi = (r.low - r.mean) / abs(r.mean), (r.high - r.mean) / abs(r.mean)
        a2.plot([lo, hi], [i, i], color="0.6", lw=4)
        a2.plot(0, i, "k|")
        v = rows[r.key]
        if v is not None:
            ok = r.low <= v <= r.high
            a2.plot((v - r.mean) / abs(r.mean), i, "o", color="C2" if ok else "C3")
        a2.plot((r.hodgins - r.mean) / abs(r.mean), i, "x", color="C0")
    a2.set_yticks(range(len(TABLE1)))
    a2.set_yticklabels([r.label for r in TABLE1], fontsize=7)
    a2.set_xlabel("relative to the human mean (grey: human range; o ours, x Hodgins 1995)")
    a2.set_xlim(-1.5, 2.5)
    a2.invert_yaxis()
    a2.set_title(f"Table 1: {result.report['table1_inside']}/16 rows inside the human range")
    fig.tight_layout()
    return save_png(fig, path)

"""The handspring vault's controller: the first five states (hurdle step, board contact, first
flight with the hands aimed by eq. 12, horse contact, the start of the second flight) as a basis
controller (:class:`Vault`) and the log of Table 1's measurements (:class:`VaultLog`)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.athletics.bodies import Athlete
from reactmocap.athletics.machine import NEXT, Basis, Context
from reactmocap.athletics.rig import per_joint
from reactmocap.athletics.sequencer import Sequencer
from reactmocap.athletics.vault_setup import HORSE, VaultParams
from reactmocap.rotations import quat_conj, quat_mul, quat_rotate
from reactmocap.sim.bodies import BALL_JOINT_INDEX as _J  # short: the poses name many joints
from reactmocap.sim.bodies import BALL_JOINTS, SIM_BODIES
from reactmocap.sim.controllers.base import FunctionController
from reactmocap.sim.controllers.machine import State, after
from reactmocap.sim.world import World

__all__ = ["Vault", "VaultLog", "VaultLogger"]

NJ = len(BALL_JOINTS)

# ---------------------------------------------------------------------------------- control


@dataclass
class VaultLog:
    """Per tick: time, COM, COM velocity, vertical force from the board and from the horse
    on the gymnast (N), whether the feet touch the board, the hands (or forearms) the horse,
    anything the floor, the lowest point of the body over the horse's top (m), the body's
    pitch and whether a forearm touches the horse."""

    rows: list[tuple] = field(default_factory=list)

    def arrays(self) -> dict[str, NDArray]:
        names = ("t", "com", "com_vel", "board_force", "horse_force", "on_board", "on_horse",
                 "on_floor", "over_horse_clearance", "pitch", "forearm_on_horse")  # fmt: skip
        if not self.rows:
            return {n: np.zeros(0) for n in names}
        return {n: np.array(c) for n, c in zip(names, zip(*self.rows))}


class Vault(Basis):
    """The vault's first five states as a basis controller; hands over to the landing."""

    name = "vault"
    initial = "hurdle"

    def __init__(self, params: VaultParams, log: VaultLog) -> None:
        self.p = params
        self.log = log

    def states(self, ctx: Context) -> list[State]:
        p = self.p
        world = ctx.world
        m = world.model
        wc = ctx.rig.wc
        rig = ctx.rig
        every = ctx.control_every
        board_geom = int(m.geom("board_plate").id)
        horse_geom = int(m.geom("horse_box").id)
        floor = int(m.geom("floor").id)
        board_dof = int(m.jnt_dofadr[m.joint("board_spring").id])
        own = world.geom_character == ctx.character
        part = world.geom_body
        feet = {SIM_BODIES.index(b) for b in ("l_foot", "r_foot")}
        forearms = {SIM_BODIES.index(b) for b in ("l_forearm", "r_forearm")}
        hands = {SIM_BODIES.index(b) for b in ("l_hand", "r_hand")} | forearms
        f6 = np.zeros(6)
        apparatus = np.array([board_geom, horse_geom])
        seen = {"board": 0, "horse": 0, "deepest": False, "blocked": False}
        # the geoms that must stay above the horse's top while over it: all but the arms'
        check = np.flatnonzero(own & ~np.isin(part, list(hands)))
        is_box = m.geom_type == int(mujoco.mjtGeom.mjGEOM_BOX)
        is_capsule = m.geom_type == int(mujoco.mjtGeom.mjGEOM_CAPSULE)
        chest = int(wc.body_ids[SIM_BODIES.index("chest")])
        sh_j = [m.joint(wc.prefix + f"{s}_shoulder").id for s in "lr"]
        horse_top = HORSE.top
        hx0 = p.horse_distance - 0.5 * HORSE.size[0]
        hx1 = p.horse_distance + 0.5 * HORSE.size[0]

        def sense(t: float) -> tuple[bool, bool, bool]:
            """Contacts with the board (feet), the horse (hands) and the floor; logs a row."""
            d = world.data
            fb = fh = 0.0
            on_b = on_h = on_f = on_fa = False
            n = d.ncon
            if n:
                # the gymnast's contacts with the board, horse and floor picked out over all
                # contacts at once; the forces then only for the board's and horse's few
                con = d.contact
                geoms, frames = con.geom[:n], con.frame
                first = own[geoms[:, 0]]
                other = np.where(first, geoms[:, 1], np.where(own[geoms[:, 1]], geoms[:, 0], -1))
                mine = np.where(first, geoms[:, 0], geoms[:, 1])
                on_f = bool((other == floor).any())
                for i in np.flatnonzero(np.isin(other, apparatus)).tolist():
                    mujoco.mj_contactForce(m, d, i, f6)
                    fz = abs(float((frames[i].reshape(3, 3).T @ f6[:3])[2]))
                    body = int(part[mine[i]])
                    if other[i] == board_geom:
                        fb += fz
                        on_b |= body in feet
                    else:
                        fh += fz
                        on_h |= body in hands
                        on_fa |= body in forearms
            s = ctx.sense(t)
            # the body's lowest point while over the horse (only the hands may touch)
            xs = d.geom_xpos[check, 0]
            over = (xs > hx0) & (xs < hx1)
            clear = math.inf
            if over.any():
                g = check[over]
                rz = np.abs(d.geom_xmat[g].reshape(-1, 3, 3)[:, 2, :])  # |R[z, j]|
                size = m.geom_size[g]
                # each geom's lowest point: a box's corners, a capsule's end cap, a sphere
                low = np.where(is_box[g], (rz * size).sum(axis=1),
                               np.where(is_capsule[g], rz[:, 2] * size[:, 1] + size[:, 0],
                                        size[:, 0]))  # fmt: skip
                clear = float((d.geom_xpos[g, 2] - low).min()) - horse_top
            pitch = _body_pitch(d, chest, ctx.athlete)
            self.log.rows.append((t, s.com.copy(), s.com_vel.copy(), fb, fh, on_b, on_h, on_f,
                                  clear, pitch, on_fa))  # fmt: skip
            return on_b, on_h, on_f

        def pose(goal: dict[int, tuple[float, float, float]], dur: float, t: float) -> None:
            g = np.full((NJ, 3), np.nan)
            for j, v in goal.items():
                g[j] = v
            rig.move(g, dur, t, list(goal))

        def stiff(values: dict[str, float]) -> None:
            rig.set_stiffness(per_joint(values))

        flight = {"waist": p.flight_stiffness, "back": p.flight_stiffness, "neck": 0.3,
                  "shoulder": 1.0, "elbow": 0.5, "wrist": 0.1, "hip": p.flight_stiffness,
                  "knee": p.flight_stiffness, "ankle": 0.5}  # fmt: skip

        # -------------------------------------------------------------- hurdle
        def hurdle_enter(_w: World, t: float) -> None:
            stiff(flight | {"hip": p.knee_stiffness, "knee": p.knee_stiffness, "ankle": 2.0})
            rig.support[:] = 0.0
            goal = {_J[f"{s}_hip"]: (p.block, 0.0, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_knee"]: (p.knee_touchdown, 0.0, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_ankle"]: (-0.2, 0.0, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_shoulder"]: (p.arms_board, 0.0, 0.0) for s in "lr"}
            pose(goal, 0.1, t)

        def hurdle(_w: World, t: float) -> None:
            sense(t)

        def on_board(_w: World, _t: float, _ti: float) -> bool:
            return bool(self.log.rows and self.log.rows[-1][5])

        # -------------------------------------------------------------- board contact
        def board_enter(_w: World, t: float) -> None:
            seen["deepest"] = False
            seen["board"] = 0

        def board(w: World, t: float) -> None:
            on_b, _, _ = sense(t)
            seen["board"] = 0 if on_b else seen["board"] + 1
            # at the board's deepest (the plate stops going down) the legs extend
            if not seen["deepest"] and w.data.qvel[board_dof] >= 0.0 and _ti_since(t) > 0.01:
                seen["deepest"] = True
                stiff(flight | {"hip": p.push_stiffness, "knee": p.push_stiffness,
                                "ankle": p.push_stiffness})  # fmt: skip
                goal = {_J[f"{s}_knee"]: (0.0, 0.0, 0.0) for s in "lr"}
                goal |= {_J[f"{s}_hip"]: (p.push_hip, 0.0, 0.0) for s in "lr"}
                goal |= {_J[f"{s}_ankle"]: (0.3, 0.0, 0.0) for s in "lr"}
                goal |= {_J[f"{s}_shoulder"]: (p.arms_push, 0.0, 0.0) for s in "lr"}
                pose(goal, 0.05, t)

        t_in = {"board": 0.0, "horse": 0.0}

        def _ti_since(t: float) -> float:
            return t - t_in["board"]

        def board_enter2(w: World, t: float) -> None:
            t_in["board"] = t
            board_enter(w, t)

        def left_board(_w: World, _t: float, t_in_state: float) -> bool:
            return t_in_state > 0.02 and seen["board"] >= 2

        # -------------------------------------------------------------- first flight
        def flight1_enter(_w: World, t: float) -> None:
            stiff(flight)
            goal = {_J[f"{s}_{j}"]: (0.0, 0.0, 0.0) for s in "lr" for j in ("knee", "elbow")}
            goal |= {_J[f"{s}_hip"]: (-p.pike, 0.0, 0.0) for s in "lr"}
            goal |= {_J[j]: (0.0, 0.0, 0.0) for j in ("waist", "back")}
            pose(goal, 0.1, t)

        def flight1(w: World, t: float) -> None:
            sense(t)
            # eq. 12: each arm points from its shoulder at the hands' place on the horse
            d = w.data
            target = np.array([p.horse_distance + p.hand_target, 0.0, horse_top])
            goal = {}
            chest_anat = quat_mul(
                d.xquat[chest], quat_conj(ctx.athlete.neutral[SIM_BODIES.index("chest")])
            )
            for k, s in enumerate("lr"):
                sh = d.xanchor[sh_j[k]].copy()
                aim = np.array([target[0], sh[1], target[2]]) - sh
                u = quat_rotate(quat_conj(chest_anat), aim / max(np.linalg.norm(aim), 1e-9))
                goal[_J[f"{s}_shoulder"]] = (float(math.atan2(-u[0], -u[2])), 0.0, 0.0)
                goal[_J[f"{s}_wrist"]] = (-0.3, 0.0, 0.0)
            pose(goal, 0.0, t)

        def on_horse(_w: World, _t: float, _ti: float) -> bool:
            return bool(self.log.rows and self.log.rows[-1][6])

        # -------------------------------------------------------------- horse contact
        def horse_enter(_w: World, t: float) -> None:
            t_in["horse"] = t
            seen["horse"] = 0
            seen["blocked"] = False
            if p.arm_spring > 0:
                # not the paper's passive strut: the arms a spring-damper that yields under
                # the arrival (shoulders give, elbows bend), then blocks (see horse())
                stiff(flight | {"shoulder": p.arm_spring, "elbow": p.arm_spring, "wrist": 0.0})
                rig.set_damping(per_joint({"shoulder": p.arm_damping, "elbow": p.arm_damping}))
                now = rig.current_angles()
                goal = {_J[f"{s}_elbow"]: (p.yield_elbow, 0.0, 0.0) for s in "lr"}
                goal |= {_J[f"{s}_shoulder"]: (now[_J[f"{s}_shoulder"], 0] + p.yield_shoulder,
                                               0.0, 0.0) for s in "lr"}  # fmt: skip
                pose(goal, 0.0, t)
                return
            values = flight | {"shoulder": p.horse_push, "wrist": 0.0, "elbow": 3.0}
            stiff(values)
            goal = {_J[f"{s}_elbow"]: (0.0, 0.0, 0.0) for s in "lr"}
            if p.horse_push > 0:
                goal |= {_J[f"{s}_shoulder"]: (-math.pi, 0.0, 0.0) for s in "lr"}
            pose(goal, 0.05, t)

        def horse(_w: World, t: float) -> None:
            _, on_h, _ = sense(t)
            seen["horse"] = 0 if on_h else seen["horse"] + 1
            if p.arm_spring > 0 and not seen["blocked"] and t - t_in["horse"] >= p.yield_s:
                # the block: the elbows straighten, the shoulders extend (girdle push)
                seen["blocked"] = True
                goal = {_J[f"{s}_elbow"]: (0.0, 0.0, 0.0) for s in "lr"}
                goal |= {_J[f"{s}_shoulder"]: (p.block_shoulder, 0.0, 0.0) for s in "lr"}
                pose(goal, p.block_s, t)

        def left_horse(_w: World, _t: float, t_in_state: float) -> bool:
            return t_in_state > 0.02 and seen["horse"] >= 2

        # -------------------------------------------------------------- second flight
        def flight2_enter(_w: World, t: float) -> None:
            stiff(flight)
            if p.arm_spring > 0:
                rig.set_damping(np.zeros(NJ))
            goal = {_J[f"{s}_hip"]: (-p.pike2, 0.08 if s == "l" else -0.08, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_knee"]: (0.0, 0.0, 0.0) for s in "lr"}
            goal |= {_J[j]: (0.0, 0.0, 0.0) for j in ("waist", "back")}
            goal |= {_J[f"{s}_shoulder"]: (p.arms_flight2, 0.0, 0.0) for s in "lr"}
            goal |= {_J[f"{s}_wrist"]: (0.0, 0.0, 0.0) for s in "lr"}
            pose(goal, 0.15, t)

        def flight2(_w: World, t: float) -> None:
            sense(t)

        def logged(fn: Callable[[World, float], None]) -> FunctionController:
            return FunctionController(fn, every)

        def after_landing(w: World, t: float) -> None:
            sense(t)

        self.after_landing = after_landing
        return [
            State("hurdle", logged(hurdle), hurdle_enter, ((on_board, "board"),)),
            State("board", logged(board), board_enter2,
                  ((left_board, "flight1"), (after(0.4), "flight1"))),
            State("flight1", logged(flight1), flight1_enter,
                  ((on_horse, "horse"), (after(1.0), "flight2"))),
            State("horse", logged(horse), horse_enter,
                  ((left_horse, "flight2"), (after(0.6), "flight2"))),
            State("flight2", logged(flight2), flight2_enter, ((after(p.layout2), NEXT),)),
        ]  # fmt: skip


def _body_pitch(d: mujoco.MjData, chest: int, ath: Athlete) -> float:
    """The chest's anatomical pitch about the run's lateral axis (rad, forward > 0; a full
    somersault is 2 pi), unwrapped by the caller."""
    q = quat_mul(d.xquat[chest], quat_conj(ath.neutral[SIM_BODIES.index("chest")]))
    up = quat_rotate(q, np.array([0.0, 0.0, 1.0]))
    return float(math.atan2(up[0], up[2]))


class VaultLogger:
    """Keeps logging the vault's rows through the landing (a controller after the sequencer)."""

    def __init__(self, vault: Vault, seq: Sequencer) -> None:
        self.vault = vault
        self.seq = seq
        self.control_every = seq.control_every

    def reset(self, world: World) -> None:
        del world

    def control(self, world: World, t: float) -> None:
        if not self.seq.state.startswith("vault."):
            self.vault.after_landing(world, t)

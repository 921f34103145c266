"""Impacts (external pushes) and contacts: an :class:`Impact` is a force or an impulse on one body
at a point; :class:`ImpactSchedule` applies a rollout's impacts through ``xfrc_applied`` with one
lever-arm rule, recomputed every step: the force at the point becomes the same force at the
body's centre of mass plus ``(p - com) x F``. Also contact reports and the kinematic scan for the
first contact between two characters."""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Literal

import mujoco
import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.sim.character import BODY_ALIASES, SIM_BODIES, Character
from reactmocap.sim.world import World

__all__ = [
    "CharacterContact",
    "ContactReport",
    "Impact",
    "ImpactSchedule",
    "KinematicContact",
    "contact_report",
    "MAX_FORCE_N",
    "MAX_IMPULSE_NS",
    "first_contact",
    "overlap_depths",
]

F64 = NDArray[np.float64]


#: the largest push accepted: beyond this a character is not pushed but destroyed (the hardest
#: human strikes peak near 10 kN; the simulation would only diverge)
MAX_FORCE_N = 20_000.0
#: the largest momentum an impact may deliver (a 75 kg body thrown at over 13 m/s)
MAX_IMPULSE_NS = 1_000.0


def _vec3(value: object, what: str) -> tuple[float, float, float]:
    try:
        arr = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise ConfigError(f"impact {what} must be 3 numbers, got {value!r}") from None
    if arr.shape != (3,):
        raise ConfigError(f"impact {what} must be 3 numbers, got {arr.size}: {value!r}")
    if not np.all(np.isfinite(arr)):
        raise ConfigError(f"impact {what} contains NaN or inf: {arr.tolist()}")
    return (float(arr[0]), float(arr[1]), float(arr[2]))


@dataclass(frozen=True)
class Impact:
    """A push on one body.

    Args:
        body: a body part (``chest``, ``l_forearm``, ...; aliases ``thorax``, ``abdomen``,
            ``neck``).
        force: ``(3,)`` world force in N; or
        impulse: ``(3,)`` world impulse in N s (exactly one of the two).
        point: application point; ``None`` = the body's centre of mass.
        frame: ``"local"`` (point in the body frame, moves with it) or ``"world"`` (point in
            world coordinates at the impact's start, then carried with the body).
        start: seconds after the rollout starts. duration: seconds (> 0; an impulse may use 0,
            meaning a single step).
        character: index of the character in the World.
    """

    body: str
    force: tuple[float, float, float] | None = None
    impulse: tuple[float, float, float] | None = None
    point: tuple[float, float, float] | None = None
    frame: Literal["local", "world"] = "local"
    start: float = 0.0
    duration: float = 0.1
    character: int = 0

    def __post_init__(self) -> None:
        try:
            body = Character.body_name(str(self.body))
        except UnknownKeyError:
            raise UnknownKeyError(
                f"impact on unknown body {self.body!r}; valid bodies are {list(SIM_BODIES)} "
                f"(aliases {dict(BODY_ALIASES)})"
            ) from None
        object.__setattr__(self, "body", body)
        if (self.force is None) == (self.impulse is None):
            raise ConfigError("an impact needs exactly one of force (N) or impulse (N s)")
        if self.force is not None:
            object.__setattr__(self, "force", _vec3(self.force, "force"))
        if self.impulse is not None:
            object.__setattr__(self, "impulse", _vec3(self.impulse, "impulse"))
        if self.point is not None:
            object.__setattr__(self, "point", _vec3(self.point, "point"))
        if self.frame not in ("local", "world"):
            raise ConfigError(f"impact frame must be 'local' or 'world', got {self.frame!r}")
        for name in ("start", "duration"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ConfigError(f"impact {name} must be a finite number of seconds, got {v!r}")
        if self.start < 0:
            raise ConfigError(f"impact start must be >= 0 s, got {self.start}")
        if self.duration < 0:
            raise ConfigError(f"impact duration must be >= 0 s, got {self.duration}")
        if self.duration == 0 and self.force is not None:
            raise ConfigError("a force impact needs a positive duration (use impulse= for a kick)")
        dt = 0.0005
        force = np.linalg.norm(self.force_vector(dt)) if self.force is not None else 0.0
        total = (np.linalg.norm(self.impulse) if self.impulse is not None
                 else force * max(self.duration, dt))  # fmt: skip
        if force > MAX_FORCE_N or total > MAX_IMPULSE_NS:
            raise ConfigError(
                f"impact of {force:.0f} N / {total:.0f} N s is beyond the physical limit this "
                f"simulation accepts ({MAX_FORCE_N:.0f} N, {MAX_IMPULSE_NS:.0f} N s): it would "
                "destroy a human body, and the simulation would diverge"
            )
        if not isinstance(self.character, int) or self.character < 0:
            raise ConfigError(f"impact character must be an index >= 0, got {self.character!r}")

    def steps(self, dt: float) -> tuple[int, int]:
        """(first step, number of steps) of the impact window."""
        return round(self.start / dt), max(1, round(self.duration / dt))

    def force_vector(self, dt: float) -> F64:
        """The world force applied during each step of the window (N)."""
        if self.force is not None:
            return np.array(self.force)
        return np.array(self.impulse) / (self.steps(dt)[1] * dt)


class ImpactSchedule:
    """A rollout's impacts resolved against a World: body ids and step windows. A window is
    ``n = max(1, round(duration / dt))`` steps from step ``round(start / dt)``; an impulse ``J``
    becomes the force ``J / (n dt)``, so the momentum delivered is exactly ``J``."""

    def __init__(self, world: World, impacts: Sequence[Impact]) -> None:
        self.world = world
        self.impacts = tuple(impacts)
        dt = world.timestep
        self._rows: list[tuple[int, int, int, F64, F64 | None, str]] = []
        for imp in self.impacts:
            if imp.character >= len(world.characters):
                raise ConfigError(
                    f"impact on character {imp.character}, but the world has "
                    f"{len(world.characters)}"
                )
            bid = world.characters[imp.character].body_id(imp.body)
            k0, n = imp.steps(dt)
            pt = None if imp.point is None else np.array(imp.point)
            self._rows.append((bid, k0, k0 + n, imp.force_vector(dt), pt, imp.frame))
        self._local_point: dict[int, F64] = {}
        self._touched: set[int] = set()

    def event_steps(self) -> list[int]:
        """Sorted steps at which :meth:`apply` changes ``xfrc_applied``: the ends of each window
        (a force at the centre of mass is constant within it), and every step of a window
        whose point moves with the body (its lever arm turns with the body)."""
        steps: set[int] = set()
        for _, k0, k1, _, pt, _ in self._rows:
            steps.update((k0, k1) if pt is None else range(k0, k1 + 1))
        return sorted(steps)

    def apply(self, step: int) -> None:
        """Set ``xfrc_applied`` for rollout step ``step`` (clears bodies whose window ended)."""
        d = self.world.data
        for bid in self._touched:
            d.xfrc_applied[bid] = 0.0
        self._touched.clear()
        for k, (bid, k0, k1, force, pt, frame) in enumerate(self._rows):
            if not k0 <= step < k1:
                continue
            rot = d.xmat[bid].reshape(3, 3)
            if pt is None:
                p = d.xipos[bid]
            elif frame == "local":
                p = d.xpos[bid] + rot @ pt
            else:
                if k not in self._local_point:  # carried with the body from the start
                    self._local_point[k] = rot.T @ (pt - d.xpos[bid])
                p = d.xpos[bid] + rot @ self._local_point[k]
            d.xfrc_applied[bid, :3] += force
            d.xfrc_applied[bid, 3:] += np.cross(p - d.xipos[bid], force)
            self._touched.add(bid)

    def clear(self) -> None:
        for bid in self._touched:
            self.world.data.xfrc_applied[bid] = 0.0
        self._touched.clear()


# ---------------------------------------------------------------------------------- contacts
@dataclass(frozen=True)
class CharacterContact:
    """One contact point between two characters. ``force`` is the world force on ``body_b``
    (character ``b``) from ``body_a`` (equal and opposite on ``body_a``)."""

    character_a: int
    body_a: str
    character_b: int
    body_b: str
    position: tuple[float, float, float]
    force: tuple[float, float, float]


@dataclass(frozen=True)
class ContactReport:
    """Contacts at one instant.

    ``ground``: per character, the bodies touching the floor (ground-support bodies);
    ``ground_force``: per character, the total world force from the floor (N);
    ``between``: character-character contacts.
    """

    time: float
    ground: tuple[tuple[str, ...], ...]
    ground_force: tuple[tuple[float, float, float], ...]
    between: tuple[CharacterContact, ...]


def _t3(v: object) -> tuple[float, float, float]:
    a = np.asarray(v, dtype=np.float64).reshape(3)
    return (float(a[0]), float(a[1]), float(a[2]))


def contact_report(world: World) -> ContactReport:
    """Who touches what, with forces (``mj_contactForce``), for the current state."""
    m, d = world.model, world.data
    char, body = world.geom_character, world.geom_body
    nchar = len(world.characters)
    ground: list[set[str]] = [set() for _ in range(nchar)]
    gforce = np.zeros((nchar, 3))
    between = []
    f6 = np.zeros(6)
    for i in range(d.ncon):
        con = d.contact[i]
        g1, g2 = int(con.geom1), int(con.geom2)
        mujoco.mj_contactForce(m, d, i, f6)
        frame = np.asarray(con.frame).reshape(3, 3)
        fw = frame.T @ f6[:3]  # on geom2 from geom1, world
        c1, c2 = int(char[g1]), int(char[g2])
        if c1 < 0 or c2 < 0:  # floor contact
            c, g, sign = (c2, g2, 1.0) if c1 < 0 else (c1, g1, -1.0)
            if c >= 0:
                ground[c].add(SIM_BODIES[body[g]])
                gforce[c] += sign * fw
        elif c1 != c2:
            between.append(
                CharacterContact(
                    c1,
                    SIM_BODIES[body[g1]],
                    c2,
                    SIM_BODIES[body[g2]],
                    _t3(con.pos),
                    _t3(fw),
                )
            )
    return ContactReport(
        time=float(d.time),
        ground=tuple(tuple(sorted(g)) for g in ground),
        ground_force=tuple(_t3(f) for f in gforce),
        between=tuple(between),
    )


@dataclass(frozen=True)
class KinematicContact:
    """First contact between two characters playing their motions kinematically.

    ``frame``/``time``: first sampled frame with contact; ``rewind_frame``/``rewind_time``: the
    last sampled (motion-capture) frame before it, where a simulation should start;
    ``pairs``: (body of character 0, body of character 1) touching at ``frame``.
    """

    frame: int
    time: float
    rewind_frame: int
    rewind_time: float
    pairs: tuple[tuple[str, str], ...]


def _kinematic_contacts(
    world: World, motions: Sequence[Motion], times: F64, margin: float = 0.0
) -> Iterator[tuple[int, list[tuple[int, int, float]]]]:
    """Per frame of ``times``: the contacts between the two characters playing their motions
    kinematically (``mj_kinematics`` + ``mj_collision``, no dynamics), as ``(geom of character
    0, geom of character 1, distance)`` (negative: penetration). Overwrites the world's state."""
    if len(world.characters) != 2 or len(motions) != 2:
        raise ConfigError("a two-character scan needs a world with two characters and two motions")
    m, d = world.model, world.data
    qs = [wc.character.qpos_from_motion(mo.sample(times))
          for wc, mo in zip(world.characters, motions)]  # fmt: skip
    char = world.geom_character
    old_margin = m.geom_margin.copy()
    m.geom_margin[:] = max(margin, 0.0)
    try:
        for k in range(times.size):
            for wc, q in zip(world.characters, qs):
                d.qpos[wc.qpos_slice] = q[k]
            mujoco.mj_kinematics(m, d)
            mujoco.mj_collision(m, d)
            # the two characters' contacts picked out over all contacts at once (a contact
            # struct per contact was most of the scan's time)
            n = d.ncon
            geoms, dist = d.contact.geom[:n], d.contact.dist[:n]
            c = char[geoms]
            keep = (c[:, 0] >= 0) & (c[:, 1] >= 0) & (c[:, 0] != c[:, 1]) & (dist <= margin)
            first = (c[keep, 0] == 0).tolist()
            pairs = geoms[keep].tolist()
            hits = [(g1, g2, dk) if f else (g2, g1, dk)
                    for (g1, g2), dk, f in zip(pairs, dist[keep].tolist(), first)]  # fmt: skip
            yield k, hits
    finally:
        m.geom_margin[:] = old_margin


def first_contact(
    world: World,
    motions: Sequence[Motion],
    fps: float = 30.0,
    start: float = 0.0,
    end: float | None = None,
    margin: float = 0.0,
) -> KinematicContact | None:
    """Scan two characters' motions at ``fps`` (kinematic playback) for the first frame where
    their geoms touch (penetration deeper than ``-margin``). Times are seconds from the
    motions' start. Returns None if they never touch. Overwrites the world's state."""
    if not (np.isfinite(fps) and fps > 0):
        raise ConfigError(f"fps must be positive, got {fps!r}")
    stop = min(mo.duration for mo in motions) if end is None else float(end)
    times = np.arange(start, stop + 1e-9, 1.0 / fps)
    body = world.geom_body
    for k, hits in _kinematic_contacts(world, motions, times, margin):
        if hits:
            rk = max(k - 1, 0)
            pairs = {(SIM_BODIES[body[a]], SIM_BODIES[body[b]]) for a, b, _ in hits}
            return KinematicContact(k + round(start * fps), float(times[k]),
                                    rk + round(start * fps), float(times[rk]),
                                    tuple(sorted(pairs)))  # fmt: skip
    return None


def overlap_depths(world: World, motions: Sequence[Motion], per_body: bool = False) -> F64:
    """Per frame of two same-rate motions, the deepest interpenetration (m) between the two
    characters' bodies playing them (0 where apart): ``(T,)``, or with ``per_body`` ``(T, 16)``
    for each body of the first character."""
    n = min(mo.num_frames for mo in motions)
    times = np.arange(n) / motions[0].fps
    out = np.zeros((n, len(SIM_BODIES)))
    body = world.geom_body
    for k, hits in _kinematic_contacts(world, motions, times):
        for g0, _, dist in hits:
            b = body[g0]
            out[k, b] = max(out[k, b], -dist)
    return out if per_body else out.max(axis=1)

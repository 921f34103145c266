"""Table 1 of Hodgins et al. 1995 (human data of Takei 1990, 24 elite female gymnasts, and the
authors' simulated vault) and :func:`table1`, which measures the same rows on a simulated
vault's log (:mod:`reactmocap.athletics.vault`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "GYMNAST_HEIGHT",
    "GYMNAST_MASS",
    "TABLE1",
    "TABLE1_KEYS",
    "Table1Row",
    "table1",
]


# ---------------------------------------------------------------------------------- Table 1
@dataclass(frozen=True)
class Table1Row:
    """One row of Table 1: its key in reports, what it measures, the unit, the human mean,
    minimum and maximum over 24 gymnasts (Takei 1990), and Hodgins et al.'s simulation."""

    key: str
    label: str
    unit: str
    mean: float
    low: float
    high: float
    hodgins: float


#: Table 1 of Hodgins, Wooten, Brogan & O'Brien 1995, "Animating Human Athletics"
#: (SIGGRAPH 95): velocities, contact times and forces of 24 elite female gymnasts at the
#: 1987 Pan American Games (Takei, Int. J. Sport Biomechanics 6:29-55, 1990) and the
#: authors' simulated vault. Transcribed from ``../shared/seeds/000_49afa289a704f6ef.txt``.
TABLE1: tuple[Table1Row, ...] = (
    Table1Row("mass_kg", "mass", "kg", 47.96, 35.5, 64.0, 64.3),
    Table1Row("height_m", "height", "m", 1.55, 1.39, 1.66, 1.64),
    Table1Row("board_contact_s", "board contact", "s", 0.137, 0.11, 0.15, 0.105),
    Table1Row("first_flight_s", "first flight", "s", 0.235, 0.14, 0.30, 0.156),
    Table1Row("horse_contact_s", "horse contact", "s", 0.245, 0.19, 0.30, 0.265),
    Table1Row("second_flight_s", "second flight", "s", 0.639, 0.50, 0.78, 0.632),
    Table1Row("board_touchdown_vx_m_s", "horizontal velocity, board touchdown", "m/s", 6.75, 5.92, 7.25, 6.75),
    Table1Row("board_liftoff_vx_m_s", "horizontal velocity, board lift-off", "m/s", 4.61, 3.97, 5.26, 4.01),
    Table1Row("horse_touchdown_vx_m_s", "horizontal velocity, horse touchdown", "m/s", 4.61, 3.97, 5.26, 4.01),
    Table1Row("horse_liftoff_vx_m_s", "horizontal velocity, horse lift-off", "m/s", 3.11, 2.48, 3.83, 2.83),
    Table1Row("board_touchdown_vz_m_s", "vertical velocity, board touchdown", "m/s", -1.15, -1.54, -0.71, -1.13),
    Table1Row("board_liftoff_vz_m_s", "vertical velocity, board lift-off", "m/s", 3.34, 2.98, 3.87, 3.81),
    Table1Row("horse_touchdown_vz_m_s", "vertical velocity, horse touchdown", "m/s", 1.26, 0.74, 2.39, 2.13),
    Table1Row("horse_liftoff_vz_m_s", "vertical velocity, horse lift-off", "m/s", 1.46, 0.56, 2.47, 1.10),
    Table1Row("board_force_n", "average vertical force, board contact", "N", 2175.0, 1396.0, 2792.0, 5075.0),
    Table1Row("horse_force_n", "average vertical force, horse contact", "N", 521.0, 309.0, 752.0, 957.0),
)  # fmt: skip
TABLE1_KEYS = tuple(r.key for r in TABLE1)
#: the Table 1 mean gymnast the vault's body is scaled to
GYMNAST_MASS = 47.96
GYMNAST_HEIGHT = 1.55


def table1(log: dict[str, NDArray], transitions: list[tuple[float, str, str]],
           mass: float, height: float) -> dict[str, float | None]:  # fmt: skip
    """Table 1's rows measured on a vault's log: contact times are from the first to the last
    tick of contact (the feet on the board, the hands on the horse), flight times between
    them and to the feet's first floor contact, velocities those of the COM at the contacts'
    first and last ticks, average forces the mean vertical contact force over the contact."""
    t = log["t"]
    out: dict[str, float | None] = {k: None for k in TABLE1_KEYS}
    out["mass_kg"] = mass
    out["height_m"] = height
    if t.size == 0:
        return out

    def span(flag: NDArray, after: float = -1.0) -> tuple[int, int] | None:
        idx = np.flatnonzero(flag & (t > after))
        if idx.size == 0:
            return None
        start = int(idx[0])
        # the first uninterrupted contact (a tick's gap is a bounce of the contact)
        stop = start
        for i in idx[1:]:
            if i - stop > 3:
                break
            stop = int(i)
        return start, stop

    board = span(log["on_board"].astype(bool))
    horse = span(log["on_horse"].astype(bool), t[board[1]] if board else -1.0)
    floor = span(log["on_floor"].astype(bool), t[horse[1]] if horse else -1.0)
    vel = log["com_vel"]
    for name, contact in (("board", board), ("horse", horse)):
        if contact:
            a, b = contact
            out[f"{name}_contact_s"] = float(t[b] - t[a])
            for event, i in (("touchdown", a), ("liftoff", b)):
                out[f"{name}_{event}_vx_m_s"] = float(vel[i, 0])
                out[f"{name}_{event}_vz_m_s"] = float(vel[i, 2])
            out[f"{name}_force_n"] = float(np.mean(log[f"{name}_force"][a : b + 1]))
    if horse:
        if board:
            out["first_flight_s"] = float(t[horse[0]] - t[board[1]])
    if floor and horse:
        out["second_flight_s"] = float(t[floor[0]] - t[horse[1]])
    del transitions
    return out

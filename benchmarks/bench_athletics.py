"""The athletics experiments (issue 18; Wooten's thesis, ch. 4, 6 and 7) on the thesis's male and
female bodies. Prints one line per experiment row with the thesis's figure beside ours, writes
the thesis-style plots and a JSON of every figure.

    python benchmarks/bench_athletics.py --tables      # rebuild the tables and supported ranges
    python benchmarks/bench_athletics.py --out docs/athletics   # the experiments and plots
    python benchmarks/bench_athletics.py --leaps --json leaps.json   # Fig. 4.1 and 4.2 only
        (into an existing results.json: replaces its leap entries only; --out redraws the two plots)
    python benchmarks/bench_athletics.py --capture --json docs/athletics/capture.json  # issue 19

``--workers N`` runs simulations in N processes (the figures do not depend on it).
``--contact NAME`` runs the experiments, ``--leaps`` or ``--capture`` on another athletics
contact model (``scene.CONTACT_MODELS``, e.g. ``elliptic``); the tables stay the default's.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from reactmocap.athletics import calibrate, run, tables
from reactmocap.athletics.plots import commanded_plot, series_plot
from reactmocap.athletics.report import ground_force
from reactmocap.athletics.scene import CONTACT_MODELS, DEFAULT_CONTACT

BODIES = ("male", "female")
ROOT = Path(__file__).resolve().parents[1]
MEASURED = ROOT / "reactmocap" / "athletics" / "measured.py"
#: thesis figures (Wooten, ch. 4, 6, 7); Table 4.1 and 4.2 rows as (command, achieved)
THESIS = {
    "broad_max": {"male": 2.12, "female": 1.57},
    "drop_max": {"male": 1.15, "female": 0.92},
    "slope": {"+X": 33.7, "-X": 38.6, "Y": 25.7},
}  # fmt: skip


def _landed(r: dict[str, Any]) -> bool:
    return bool(r.get("landed")) and r.get("status") == "ok"


# ---------------------------------------------------------------------------------- tables
def build_tables(
    workers: int, parts: tuple[str, ...] = ("leap", "com", "broad", "land")
) -> dict[str, Any]:
    """Rebuild the measured tables and supported ranges (``parts``: which; the others are
    kept as they are in measured.py)."""
    from reactmocap.athletics import measured

    grid = [{"effort": round(s, 3)} for s in np.linspace(0.0, 1.0, 41)]
    out: dict[str, Any] = {
        "LEAP_TABLES": dict(measured.LEAP_TABLES),
        "BROAD_TABLES": dict(measured.BROAD_TABLES),
        "LANDING_DELTAS": dict(measured.LANDING_DELTAS),
    }
    supported: dict[Any, dict[str, tuple[float, float]]] = {
        k: dict(v) for k, v in measured.SUPPORTED.items()
    }
    lifted = lambda r: r["time_to_liftoff_s"] is not None  # noqa: E731
    for body in BODIES:
        t0 = time.time()
        if "leap" in parts:
            # the effort table is the timed push's (the com push plans its height itself)
            leaps = calibrate.sweep("leap", body, [{**g, "push": "timed"} for g in grid], workers)
            table = calibrate.effort_table(leaps, "achieved_height_m", lifted)
            out["LEAP_TABLES"][body] = table
            # supported: the longest stretch of the table's heights whose leaps land
            ok = {round(float(r["achieved_height_m"]), 4): _landed(r) for r in leaps}
            heights = [v for _, v in table]
            rng = _longest(heights, [ok.get(v, False) for v in heights])
            if rng:
                supported.setdefault(("leap", "height"), {})[body] = rng
        if "com" in parts:
            rng = _com_range(body, workers)
            if rng:
                supported.setdefault(("leap", "height", "com"), {})[body] = rng
        if "broad" in parts:
            broads = calibrate.sweep("broad-jump", body, grid, workers)
            # over the jumps that land only: a command interpolates between landed jumps
            btable = calibrate.effort_table(broads, "achieved_distance_m", _landed)
            out["BROAD_TABLES"][body] = btable
            # supported: the table's jumps over the stretch of efforts from 0 that all land (a
            # command past an effort that falls interpolates across it, and may fall too)
            efforts = [g["effort"] for g in grid]
            rng = calibrate.contiguous_range(efforts, [_landed(r) for r in broads], 0.0)
            inside = [v for s, v in btable if rng and rng[0] <= s <= rng[1]]
            if inside:
                supported.setdefault(("broad-jump", "distance"), {})[body] = (
                    min(inside),
                    max(inside),
                )
        if "deltas" in parts:  # before "land" (a later run): its ranges use this table
            out["LANDING_DELTAS"][body] = _delta_table(body, workers)
        if "land" in parts:
            drops = np.round(np.arange(0.0, 2.51, 0.1), 2)
            dr = calibrate.sweep("land", body, [{"drop": float(d)} for d in drops], workers)
            rng = calibrate.contiguous_range(drops, [_landed(r) for r in dr], 0.0)
            if rng:
                supported.setdefault(("land", "drop"), {})[body] = rng
            vxs = np.round(np.arange(-2.0, 4.01, 0.25), 2)
            drop = _drop_for_com(body, 1.25)
            grid_v = [{"drop": drop, "vx": float(v)} for v in vxs]
            vr = calibrate.sweep("land", body, grid_v, workers)
            rng = calibrate.contiguous_range(vxs, [_landed(r) for r in vr], 0.0)
            if rng:
                supported.setdefault(("land", "vx"), {})[body] = rng
            slopes = _slope_limits(body, workers, seconds=TABLE_SLOPE_SECONDS)
            supported.setdefault(("balance", "slope"), {})[body] = (
                0.0,
                math.radians(min(slopes.values())),
            )
        print(f"{body}: {','.join(parts)} tables in {time.time() - t0:.0f} s")
    out["SUPPORTED"] = supported
    out["MEASURED_ON"] = f"{datetime.date.today().isoformat()} (bench_athletics.py --tables)"
    header = "Measured tables (written by ``benchmarks/bench_athletics.py --tables``; do not edit)."
    calibrate.write_measured(MEASURED, out, header)
    return out


#: the landing delta table's grid (thesis Table 6.1): horizontal velocities (m/s), deltas (m)
DELTA_VELOCITIES = np.round(np.arange(-1.0, 3.01, 0.5), 2)
DELTA_GRID = np.round(np.arange(-0.8, 0.31, 0.02), 2)  # her 3 m/s window is near -0.65


def _land_with_delta(job: tuple[str, float, float, float]) -> bool:
    """Whether a landing at ``vx`` lands with one foot-servo delta (in a worker process)."""
    body, drop, vx, delta = job
    tables.LANDING_DELTAS = {body: ((0.0, delta),)}  # one row: this delta at every speed
    tables.LANDING_DELTAS_FAST = {}  # (its rows would be appended above 0 m/s)
    return _landed(run("land", body, drop=drop, vx=vx, check_range=False).report)


def _delta_table(body: str, workers: int) -> tuple[tuple[float, float], ...]:
    """Thesis Table 6.1 for our landing: per horizontal velocity (COM 1.25 m up), the middle
    of the longest stretch of deltas that land; a velocity where none lands is left out."""
    from concurrent.futures import ProcessPoolExecutor

    drop = _drop_for_com(body, 1.25)
    jobs = [(body, drop, float(v), float(d)) for v in DELTA_VELOCITIES for d in DELTA_GRID]
    with ProcessPoolExecutor(max(workers, 1)) as ex:  # always apart: the jobs patch tables
        ok = list(ex.map(_land_with_delta, jobs))
    n = len(DELTA_GRID)
    rows = []
    for i, v in enumerate(DELTA_VELOCITIES):
        rng = _longest([float(d) for d in DELTA_GRID], ok[i * n : (i + 1) * n])
        if rng:
            rows.append((float(v), round((rng[0] + rng[1]) / 2.0, 3)))
    return tuple(rows)


def _longest(values: list[float], ok: list[bool]) -> tuple[float, float] | None:
    best: tuple[int, int] | None = None
    i = 0
    while i < len(values):
        if ok[i]:
            j = i
            while j + 1 < len(values) and ok[j + 1]:
                j += 1
            if best is None or j - i > best[1] - best[0]:
                best = (i, j)
            i = j + 1
        else:
            i += 1
    return None if best is None else (values[best[0]], values[best[1]])


#: the "com" push's commands for its supported range (m): a 0.025 m grid
COM_RANGE_GRID = np.round(np.arange(0.05, 1.2001, 0.025), 3)


def _com_range(body: str, workers: int) -> tuple[float, float] | None:
    """The "com" push's supported leap heights: the longest stretch of :data:`COM_RANGE_GRID`
    commands that land (as the timed push's range: its table's heights that land; the
    accuracy is printed, not part of the range)."""
    grid = [{"height": float(h), "push": "com"} for h in COM_RANGE_GRID]
    rows = calibrate.sweep("leap", body, grid, workers)
    for r in rows:
        print(f"  com {body} {r['height']:.3f} m: error "
              f"{100 * (r['achieved_height_m'] - r['height']):+.1f} cm, landed {_landed(r)}, "
              f"lift-off pitch momentum {r['liftoff_pitch_momentum']:+.2f}", flush=True)  # fmt: skip
    return _longest([float(h) for h in COM_RANGE_GRID], [_landed(r) for r in rows])


def _drop_for_com(body: str, com_height: float) -> float:
    """Sole clearance that puts the landing pose's COM at ``com_height`` m (thesis ch. 6)."""
    from reactmocap.athletics.behaviours import LANDING_LEG
    from reactmocap.athletics.bodies import athlete
    from reactmocap.athletics.scene import stand_angles

    ath = athlete(body)
    q = ath.standing_qpos(stand_angles(ath, LANDING_LEG), clearance=0.0)
    return round(com_height - float(ath.com_of(q)[2]), 3)


# ---------------------------------------------------------------------------------- searches
def _largest(ok: Any, lo: float, hi: float, step: float) -> float:
    """Largest value in [lo, hi] on a ``step`` grid for which ``ok`` holds, assuming it holds
    below and fails above (bisection)."""
    if not ok(lo):
        return float("nan")
    if ok(hi):
        return hi
    a, b = lo, hi
    while b - a > step + 1e-9:
        mid = round((a + b) / 2 / step) * step
        if mid in (a, b):
            break
        if ok(mid):
            a = mid
        else:
            b = mid
    return a


def _contiguous(ok: Any, lo: float, hi: float, step: float) -> float:
    """Largest value on a ``step`` grid from ``lo`` such that ``ok`` holds at every grid value
    up to it (nan if not at ``lo``). Why beside :func:`_largest`: a push limit is not monotone
    (a held push above moving ones), and the bisection can land on such an island: 7 of the 16
    ``step="on"`` limits did (docs/athletics.md, "How much of the 16 limits stands on islands")."""
    last = float("nan")
    for v in np.arange(lo, hi + step / 2, step):
        if not ok(float(v)):
            break
        last = round(float(v), 9)
    return last


def _pool(
    fn: Any, body: str, dirs: list[float], workers: int, contact: str = DEFAULT_CONTACT,
    *extra: Any,
) -> list[float]:  # fmt: skip
    """``fn(body, direction, contact, *extra)`` for each direction, in ``workers`` processes."""
    if workers <= 1:
        return [fn(body, d, contact, *extra) for d in dirs]
    from concurrent.futures import ProcessPoolExecutor

    n = len(dirs)
    with ProcessPoolExecutor(workers) as ex:
        return list(ex.map(fn, [body] * n, dirs, [contact] * n, *([e] * n for e in extra)))


#: seconds a COM offset or a slope (after its 2 s ramp) is run before it is judged: run 3 s,
#: his back-diagonal offsets drifted and fell by 8 s, and on every slope the feet crept
#: downhill (docs/athletics.md, "The Fig. 7.5 offsets and the slopes judged at 8 s")
STAND_SECONDS = 8.0
#: the supported slope range (``--tables``) is what the library's default run balances
#: (``run("balance")``'s ``seconds``, 3 s), not the benchmark's longer judge
TABLE_SLOPE_SECONDS = 3.0


def _slope_held(body: str, direction: float, contact: str, seconds: float) -> Any:
    return lambda deg: bool(run("balance", body, check_range=False, seconds=seconds,
                                slope=math.radians(deg), slope_dir=math.radians(direction),
                                contact=contact).report["balanced"])  # fmt: skip


def _slope_limit(
    body: str, direction: float, contact: str = DEFAULT_CONTACT, seconds: float = STAND_SECONDS
) -> float:
    return _largest(_slope_held(body, direction, contact, seconds), 0.0, 45.0, 0.5)


def _slope_limits(
    body: str, workers: int, contact: str = DEFAULT_CONTACT, seconds: float = STAND_SECONDS
) -> dict[str, float]:
    dirs = {"+X": 0.0, "-X": 180.0, "Y": 90.0}
    lims = _pool(_slope_limit, body, list(dirs.values()), workers, contact, seconds)
    return dict(zip(dirs, lims))


#: seconds a pushed body is run before it is judged (the push at 1.0-1.25 s): run 3 s, five of
#: the 16 default limits were a body still on one foot that fell by 5 s (docs/athletics.md,
#: "The Fig. 7.7 pushes judged at 8 s")
PUSH_SECONDS = 8.0


def _push_held(body: str, direction: float, contact: str) -> Any:
    return lambda f: bool(run("balance", body, check_range=False, seconds=PUSH_SECONDS, push=f,
                              push_dir=math.radians(direction),
                              contact=contact).report["balanced"])  # fmt: skip


def _push_limit(body: str, direction: float, contact: str = DEFAULT_CONTACT) -> float:
    return _largest(_push_held(body, direction, contact), 0.0, 600.0, 5.0)


def _push_contiguous(body: str, direction: float, contact: str = DEFAULT_CONTACT) -> float:
    return _contiguous(_push_held(body, direction, contact), 0.0, 600.0, 5.0)


def _offset_held(body: str, direction: float, contact: str) -> Any:
    a = math.radians(direction)
    return lambda m: bool(run("balance", body, check_range=False, seconds=STAND_SECONDS,
                              com_offset_x=m * math.cos(a), com_offset_y=m * math.sin(a),
                              contact=contact).report["balanced"])  # fmt: skip


def _offset_limit(body: str, direction: float, contact: str = DEFAULT_CONTACT) -> float:
    return _largest(_offset_held(body, direction, contact), 0.0, 0.3, 0.005)


# ---------------------------------------------------------------------------------- experiments
def _leap_experiments(body: str, workers: int, res: dict[str, Any], panels: dict[str, Any],
                      grf_curves: dict[str, Any], contact: str = DEFAULT_CONTACT,
                      ) -> list[tuple[float, float]]:  # fmt: skip
    """Fig. 4.1 and 4.2 for one body into ``res`` (``leap_<body>``, ``leap05_<body>``);
    returns the runs' real-time factors (wall, CPU)."""
    commands = [round(x, 2) for x in np.linspace(0.1, 1.0, 10)]
    rows = calibrate.sweep("leap", body, [{"height": h, "contact": contact} for h in commands],
                           workers)  # fmt: skip
    speeds = [(r["realtime_factor"], r["realtime_factor_cpu"]) for r in rows]
    got = [r["achieved_height_m"] for r in rows]
    err = [abs(g - c) for g, c in zip(got, commands)]
    res[f"leap_{body}"] = {
        "commanded": commands, "achieved": got, "abs_error": err,
        "landed": [_landed(r) for r in rows], "max_abs_error": max(err),
        "human_plausible": [r["human_plausible"] for r in rows],
        "peak_joint_torque_nm": [r["peak_joint_torque_nm"] for r in rows],
        "peak_joint_power_w": [r["peak_joint_power_w"] for r in rows],
    }  # fmt: skip
    panels[body] = (commands, got)
    half = calibrate.sweep("leap", body, [{"height": 0.5, "contact": contact}], 1)[0]
    res[f"leap05_{body}"] = {k: half[k] for k in ("time_to_liftoff_s", "peak_grf_bw",
                                                   "achieved_height_m", "landed")}  # fmt: skip
    for h in (0.2, 0.5, 0.8):
        r = run("leap", body, height=h, check_range=False, contact=contact)
        t, force = ground_force(r.log, r.report["mass_kg"], np.array([0.0, 0.0, -9.81]))
        grf_curves[f"{body} {h} m"] = (t, force[:, 2] / (r.report["mass_kg"] * 9.81))
    return speeds


def experiments(out: Path | None, workers: int, contact: str = DEFAULT_CONTACT) -> dict[str, Any]:
    res: dict[str, Any] = {"date": datetime.date.today().isoformat()}
    if contact != DEFAULT_CONTACT:
        res["contact"] = contact
    c = {"contact": contact}
    speeds: list[tuple[float, float]] = []
    panels: dict[str, Any] = {}
    grf_curves: dict[str, Any] = {}
    for body in BODIES:
        speeds += _leap_experiments(body, workers, res, panels, grf_curves, contact)
        # broad jump: commanded over the table's span, and the longest landed jump
        btable = tables.BROAD_TABLES.get(body, ())
        if btable:
            span = np.linspace(btable[0][1], btable[-1][1], 6)
            brows = calibrate.sweep("broad-jump", body,
                                    [{"distance": float(d), **c} for d in span], workers)  # fmt: skip
            bgot = [r["achieved_distance_m"] for r in brows]
            landed = [_landed(r) for r in brows]
            # the longest jump that landed (the table's end is the longest that lifted off)
            res[f"broad_{body}"] = {"commanded": span.tolist(), "achieved": bgot,
                                    "abs_error": [abs(a - b) for a, b in zip(bgot, span)],
                                    "landed": landed, "longest": btable[-1][1],
                                    "max_landed": max((a for a, ok in zip(bgot, landed) if ok),
                                                      default=None)}  # fmt: skip
        # landing
        drops = np.round(np.arange(0.1, 2.51, 0.1), 2)
        dr = calibrate.sweep("land", body, [{"drop": float(d), **c} for d in drops], workers)
        rng = calibrate.contiguous_range(drops, [_landed(r) for r in dr], 0.1)
        res[f"drop_{body}"] = {"max_landed": rng[1] if rng else None,
                               "landed": {float(d): _landed(r) for d, r in zip(drops, dr)}}  # fmt: skip
        drop = _drop_for_com(body, 1.25)
        vxs = np.round(np.arange(-2.0, 4.01, 0.25), 2)
        vr = calibrate.sweep("land", body, [{"drop": drop, "vx": float(v), **c} for v in vxs],
                             workers)  # fmt: skip
        rng = calibrate.contiguous_range(vxs, [_landed(r) for r in vr], 0.0)
        res[f"vx_{body}"] = {"range": rng, "drop_m": drop,
                             "landed": {float(v): _landed(r) for v, r in zip(vxs, vr)}}  # fmt: skip
        # balance
        dirs = [0, 45, 90, 135, 180, 225, 270, 315]
        res[f"push_{body}"] = dict(zip(dirs, _pool(_push_limit, body, dirs, workers, contact)))
        res[f"push_contiguous_{body}"] = dict(
            zip(dirs, _pool(_push_contiguous, body, dirs, workers, contact))
        )
        res[f"offset_{body}"] = dict(zip(dirs, _pool(_offset_limit, body, dirs, workers, contact)))
        res[f"slope_{body}"] = _slope_limits(body, workers, contact)
    # backpack (female, no re-tuning): horizontal-velocity landings with 2 and 4 kg
    drop = _drop_for_com("female", 1.25)
    for kg in (2.0, 4.0):
        rows = calibrate.sweep("land", "female", [{"drop": drop, "vx": v, "backpack": kg, **c}
                                                  for v in (-1.0, 0.0, 1.0, 2.0, 3.0)], workers)  # fmt: skip
        res[f"backpack_{int(kg)}kg"] = {v: _landed(r) for v, r in
                                        zip((-1.0, 0.0, 1.0, 2.0, 3.0), rows)}  # fmt: skip
    res["speed"] = {"wall_median": float(np.median([s[0] for s in speeds])),
                    "cpu_median": float(np.median([s[1] for s in speeds]))}  # fmt: skip
    if out is not None:
        plots(res, grf_curves, out)
    return res


def plots(res: dict[str, Any], grf_curves: dict[str, Any] | None, out: Path) -> None:
    """The thesis-style figures from the experiments' results (``--replot`` redraws them
    from the JSON, without the ground-force curves)."""
    out.mkdir(parents=True, exist_ok=True)
    panels = {b: (res[f"leap_{b}"]["commanded"], res[f"leap_{b}"]["achieved"]) for b in BODIES}
    commanded_plot(panels, out / "fig4_1_vertical_leap.png", quantity="height")
    if grf_curves:
        series_plot(grf_curves, out / "fig4_2_ground_force.png", xlabel="time (s)",
                    ylabel="vertical GRF (body weights)", title="Leaps, ground reaction force")  # fmt: skip
    bpanels = {b: (res[f"broad_{b}"]["commanded"], res[f"broad_{b}"]["achieved"])
               for b in BODIES if f"broad_{b}" in res}  # fmt: skip
    if bpanels:
        commanded_plot(bpanels, out / "fig4_4_broad_jump.png", quantity="distance")
    _polar_plot(res, out)


def _polar_plot(res: dict[str, Any], out: Path) -> None:
    from reactmocap.response.plots import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(9, 8), dpi=100)
    for row, body in enumerate(BODIES):
        for col, (key, unit) in enumerate((("offset", "m"), ("push", "N"))):
            ax = axes[row, col]
            data = res[f"{key}_{body}"]
            ang = np.radians(list(data)) if data else np.zeros(0)
            mag = np.array(list(data.values()), dtype=float)
            ax.plot(np.append(mag * np.cos(ang), mag[:1] * np.cos(ang[:1])),
                    np.append(mag * np.sin(ang), mag[:1] * np.sin(ang[:1])), "o-")  # fmt: skip
            ax.axhline(0, color="0.8")
            ax.axvline(0, color="0.8")
            ax.set_aspect("equal")
            ax.set_title(f"{body}: largest {'COM offset' if key == 'offset' else 'push'} ({unit})")
            ax.set_xlabel(f"X ({unit})")
            ax.set_ylabel(f"Y ({unit})")
    from reactmocap.io import save_png

    fig.tight_layout()
    save_png(fig, out / "fig7_5_7_7_balance.png")


def print_table(res: dict[str, Any]) -> None:
    def fmt(x: Any) -> str:
        return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.3g}"

    print(f"athletics experiments, {res['date']}")
    for b in BODIES:
        lp = res[f"leap_{b}"]
        print(f"Fig 4.1 {b}: max |error| {fmt(lp['max_abs_error'])} m over 0.1-1.0 m; landed "
              f"{sum(lp['landed'])}/10; human-plausible {sum(lp['human_plausible'])}/10")  # fmt: skip
        h = res[f"leap05_{b}"]
        print(f"Fig 4.2 {b} 0.5 m: lift-off {fmt(h['time_to_liftoff_s'])} s, push-off peak "
              f"{fmt(h['peak_grf_bw'])} BW (thesis male 1.1 s, 5.8 BW; human 1.1 s, 2.5 BW)")  # fmt: skip
        if f"broad_{b}" in res:
            br = res[f"broad_{b}"]
            print(f"Fig 4.4 {b}: max |error| {fmt(max(br['abs_error']))} m; longest landed "
                  f"{fmt(br['max_landed'])} m of the 6, longest {fmt(br.get('longest'))} m "
                  f"(thesis {THESIS['broad_max'][b]} m)")  # fmt: skip
        print(f"Ch 6 drop {b}: highest landed {fmt(res[f'drop_{b}']['max_landed'])} m "
              f"(thesis {THESIS['drop_max'][b]} m)")  # fmt: skip
        print(f"Ch 6 vx {b}: landed range {res[f'vx_{b}']['range']} m/s (thesis -1.0 to 3.0)")
        print(f"Fig 7.5 {b}: largest COM offset by direction {res[f'offset_{b}']}")
        print(f"Fig 7.7 {b}: largest push by direction {res[f'push_{b}']}")
        if f"push_contiguous_{b}" in res:  # results from before 2026-12-05 lack it
            print(f"Fig 7.7 {b}: largest push with every smaller one held "
                  f"{res[f'push_contiguous_{b}']}")  # fmt: skip
        print(f"Ch 7 slope {b}: {res[f'slope_{b}']} (thesis male {THESIS['slope']})")
    for kg in (2, 4):
        print(f"Table 6.2 female {kg} kg: landed by vx {res[f'backpack_{kg}kg']}")
    print(f"speed: median {res['speed']['wall_median']:.2f}x real time (wall, shared machine), "
          f"{res['speed']['cpu_median']:.2f}x (CPU time); thesis 70x slower")  # fmt: skip


def capture(workers: int, starts: int = 50, contact: str = DEFAULT_CONTACT) -> dict[str, Any]:
    """Issue 19's capture regions: each working maneuver from ``starts`` perturbed starts
    (``Perturbation.sample``: 3 deg per joint axis, 2 deg pelvis pitch, 0.05 m/s, 0.1 rad/s;
    and the same at a tenth of that), success = landed and not fell."""
    from reactmocap.athletics.maneuvers import capture_region, load_maneuver

    out: dict[str, Any] = {}
    for name in ("back_somersault", "back_somersault_female", "back_layout", "vertical_leap",
                 "broad_jump", "dive_pike", "back_handspring", "back_handspring_female",
                 "forward_somersault"):  # fmt: skip
        m = load_maneuver(ROOT / "examples" / "athletics" / "maneuvers" / f"{name}.toml")
        for label, scale in (("full", 1.0), ("tenth", 0.1)):
            sd = {"joint_sd": math.radians(3.0) * scale, "pitch_sd": math.radians(2.0) * scale,
                  "velocity_sd": 0.05 * scale, "spin_sd": 0.1 * scale}  # fmt: skip
            t0 = time.time()
            r = capture_region(m, starts=starts, workers=workers, contact=contact, **sd)
            out[f"{name}_{label}"] = r
            print(f"capture {name} ({label} perturbation): landed {r['landed']}/{starts} "
                  f"({100 * r['success_rate']:.0f}%; thesis: not measured; goal >= 90%) "
                  f"[{time.time() - t0:.0f} s]", flush=True)  # fmt: skip
            for key, reg in r["region"].items():
                print(f"    {key}: median {reg['median']:.3g}, success below/above it "
                      f"{reg['success_below_median']:.0%}/{reg['success_above_median']:.0%}, "
                      f"largest that landed {reg['largest_success']}")  # fmt: skip
    return out


def _leaps_only(
    workers: int, path: Path | None, out: Path | None, contact: str = DEFAULT_CONTACT
) -> int:
    """``--leaps``: Fig. 4.1 and 4.2 only. An existing ``--json`` file keeps its other
    figures (its ``leap_*`` entries are replaced and dated ``leaps_date``); ``--out`` redraws
    those two plots."""
    today = datetime.date.today().isoformat()
    res: dict[str, Any] = {}
    grf_curves: dict[str, Any] = {}
    for body in BODIES:
        _leap_experiments(body, workers, res, {}, grf_curves, contact)
        row, half = res[f"leap_{body}"], res[f"leap05_{body}"]
        print(f"{body}: achieved {np.round(row['achieved'], 3).tolist()}, landed "
              f"{sum(row['landed'])}/10 {row['landed']}; 0.5 m: {half}")  # fmt: skip
    if out is not None:
        panels = {b: (res[f"leap_{b}"]["commanded"], res[f"leap_{b}"]["achieved"]) for b in BODIES}
        out.mkdir(parents=True, exist_ok=True)
        commanded_plot(panels, out / "fig4_1_vertical_leap.png", quantity="height")
        series_plot(grf_curves, out / "fig4_2_ground_force.png", xlabel="time (s)",
                    ylabel="vertical GRF (body weights)", title="Leaps, ground reaction force")  # fmt: skip
    if path is not None:
        from reactmocap.io import atomic_write_text

        full = json.loads(path.read_text()) if path.exists() else {"date": today}
        full.update(res)
        full["leaps_date"] = today
        atomic_write_text(path, json.dumps(full, indent=1, default=str) + "\n")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--tables", action="store_true", help="rebuild tables and ranges")
    ap.add_argument("--parts", default="leap,com,broad,land",
                    help="with --tables: which of leap,com,broad,deltas,land to rebuild "
                         "(com: the com push's supported heights; deltas: the landing's "
                         "Table 6.1, ~15 min; run it before land)")  # fmt: skip
    ap.add_argument("--out", type=Path, help="folder for the plots")
    ap.add_argument("--json", type=Path, help="write every figure as JSON")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--capture", action="store_true",
                    help="issue 19: capture regions of the example maneuvers (50 starts each)")  # fmt: skip
    ap.add_argument("--replot", type=Path, help="redraw the plots from a --json file into --out")
    ap.add_argument("--leaps", action="store_true",
                    help="only Fig. 4.1 and 4.2 (the vertical leaps), both bodies, into --json")  # fmt: skip
    ap.add_argument("--contact", choices=list(CONTACT_MODELS), default=DEFAULT_CONTACT,
                    help="athletics contact model of every run (not with --tables: the "
                         "tables are the default's)")  # fmt: skip
    args = ap.parse_args()
    if args.tables and args.contact != DEFAULT_CONTACT:
        ap.error(f"--tables builds the default ({DEFAULT_CONTACT}) contact model's tables")
    if args.leaps:
        return _leaps_only(args.workers, args.json, args.out, args.contact)
    if args.tables:
        build_tables(args.workers, tuple(args.parts.split(",")))
        return 0
    if args.capture:
        res = capture(args.workers, contact=args.contact)
        if args.json is not None:
            from reactmocap.io import atomic_write_text

            atomic_write_text(args.json, json.dumps(res, indent=1, default=str) + "\n")
        return 0
    if args.replot is not None:
        res = json.loads(args.replot.read_text())
        for key in list(res):  # JSON keys of the direction tables are strings
            if key.startswith(("push_", "offset_")):
                res[key] = {float(k): v for k, v in res[key].items()}
        plots(res, None, args.out or args.replot.parent)
        print_table(res)
        return 0
    res = experiments(args.out, args.workers, args.contact)
    print_table(res)
    if args.json is not None:
        from reactmocap.io import atomic_write_text

        atomic_write_text(args.json, json.dumps(res, indent=1, default=str) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

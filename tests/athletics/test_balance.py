"""Balance (thesis ch. 7): standing, pushes on the chest, posture, slopes and a backpack."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from reactmocap.athletics import balance, behaviours, run
from reactmocap.athletics.balance import STANDING_GAINS, BalanceGains, BalanceLaw, Step
from reactmocap.athletics.behaviours import AthleticsResult
from reactmocap.athletics.maneuvers import (
    Maneuver,
    Perturbation,
    Phase,
    load_maneuver,
    run_maneuver,
)
from reactmocap.athletics.report import FALL_HEIGHT
from reactmocap.cli import main
from reactmocap.errors import ConfigError


def test_a_50_newton_push_is_recovered() -> None:
    r = run("balance", "male", seconds=2.5, push=50.0, push_dir=0.0)
    assert r.report["balanced"] and not r.report["fell"]
    assert r.report["max_com_offset_m"] < 0.1


def test_a_2000_newton_push_falls() -> None:
    r = run("balance", "male", seconds=2.5, push=2000.0, push_dir=0.0)
    assert r.report["fell"]
    assert not r.report["balanced"]


def test_pelvis_height_and_torso_pitch_are_held() -> None:
    r = run("balance", "female", seconds=2.5, pelvis_height=0.72, pitch=math.radians(20))
    assert r.report["balanced"]
    world = r.rollout.world
    data = world.data
    m = world.model
    # the knees make the hip-ankle distance the height asked for less the ankle's height
    legs = [np.linalg.norm(data.xanchor[m.joint(f"a/{s}_hip").id]
                           - data.xanchor[m.joint(f"a/{s}_ankle").id]) for s in "lr"]  # fmt: skip
    ankle = np.mean([data.xanchor[m.joint(f"a/{s}_ankle").id][2] for s in "lr"])
    assert float(np.mean(legs)) == pytest.approx(0.72 - ankle, abs=0.02)
    # the pelvis leans forward about as asked (plus the squat's lean)
    pelvis = data.xmat[world.characters[0].body_ids[0]].reshape(3, 3)
    pitch = math.degrees(math.atan2(-pelvis[2, 0], pelvis[0, 0]))
    assert 15.0 < pitch < 45.0


def test_balance_on_a_slope_and_with_a_backpack() -> None:
    r = run("balance", "male", seconds=1.0, slope=math.radians(12.0))
    assert r.report["balanced"]
    r = run("balance", "female", seconds=2.0, backpack=4.0)
    assert r.report["balanced"] and r.report["mass_kg"] == pytest.approx(53.3, abs=0.01)


def test_the_com_target_moves_uphill_on_a_sideways_slope() -> None:
    # the balance command's STANDING_GAINS: with the thesis's target (the support centre) she
    # slid downhill and fell from 19.5 deg on (2026-12-02); now she stands on 23 deg
    r = run(
        "balance", "female", seconds=3.0, slope=math.radians(23.0), slope_dir=math.radians(90.0)
    )
    assert r.report["balanced"] and not r.report["fell"]
    with pytest.raises(ConfigError):
        BalanceGains(uphill=(0.0, math.nan))


def test_a_body_that_slides_upright_down_a_steep_slope_has_not_fallen() -> None:
    # the fall's pelvis height is measured above the floor plane, along its normal: at 37 deg
    # the male slides down the slope on both feet, his pelvis lower in the world than
    # FALL_HEIGHT of its standing height, which a world-z height called a fall (2026-12-06)
    r = run("balance", "male", check_range=False, seconds=8.0, slope=math.radians(37.0))
    assert not r.report["fell"] and r.report["on_both_feet"]
    world = r.rollout.world
    standing = float(r.log["pelvis"][0])
    root = world.model.body("a/pelvis").id
    assert world.data.xpos[root][2] < FALL_HEIGHT * standing < float(r.log["pelvis"][-1])


def test_on_a_sideways_slope_the_hips_shift_the_weight_and_the_feet_stay_flat() -> None:
    # STANDING_GAINS.side_roll: the thesis's ankle roll offset tipped the feet onto their
    # downhill edges and they crept downhill, 6-8 cm/s at 24.5 deg (0.35 m in the run), and
    # the male fell from 24 deg on (2026-12-02); with the sideways offset on the hips he stands
    # on 27 deg and his feet creep 2-4 cm/s (0.14-0.18 m in the run)
    r = run(
        "balance", "male", check_range=False, seconds=3.0, slope=math.radians(27.0),
        slope_dir=math.radians(90.0),
    )  # fmt: skip
    assert r.report["balanced"] and not r.report["fell"]
    world = r.rollout.world
    ankles = [world.model.joint(f"a/{s}_ankle").id for s in "lr"]
    # the feet start at y = +-0.088 m (across the slope, -y downhill)
    slid = np.array([0.088, -0.088]) - world.data.xanchor[ankles, 1]
    assert slid.max() < 0.25
    with pytest.raises(ConfigError):
        BalanceGains(side_roll=(math.inf, 0.0))


def test_a_forward_push_past_the_ankles_is_taken_by_the_hips() -> None:
    # STANDING_GAINS.bow: 135 N forward for 0.25 s puts the capture point past the toes (the
    # ankles alone: 120 N, the heels lift and the COM creeps over the toes, 2026-12-02); the
    # trunk bows toward the fall and the body stands again on its feet: no step or hop (the
    # contacts flicker for 4-5 ticks as the bow comes back; a bow at gain 30 hopped for 160)
    r = run("balance", "male", check_range=False, seconds=3.0, push=135.0, push_dir=0.0)
    assert r.report["balanced"] and not r.report["fell"]
    log = r.log
    after = log["t"] >= 0.5
    assert np.count_nonzero(log["feet"][after] < 2) <= 10
    lean = log["trunk"][:, 0]  # the pelvis-to-head line's forward part
    assert lean[after].max() > 0.3 and abs(lean[-1]) < 0.1
    with pytest.raises(ConfigError, match="bow"):
        BalanceGains(bow=(20.0, -0.05, 1.0, 0.35))


def test_a_backward_push_is_taken_by_the_arms(monkeypatch: pytest.MonkeyPatch) -> None:
    # STANDING_GAINS.arms: 185 N back for 0.25 s; the arms rise forward while the capture point
    # lies behind the COM target and the male stands; without them he falls (the limit was
    # 175 N with the bow alone, 2026-12-03); without the windmilling, which alone also takes it
    base = dataclasses.replace(STANDING_GAINS, windmill=None)
    monkeypatch.setattr(behaviours, "STANDING_GAINS", base)
    push = {"check_range": False, "seconds": 3.0, "push": 185.0, "push_dir": math.pi}
    r = run("balance", "male", **push)
    assert r.report["balanced"] and not r.report["fell"]
    no_arms = dataclasses.replace(base, arms=None)
    monkeypatch.setattr(behaviours, "STANDING_GAINS", no_arms)
    assert not run("balance", "male", **push).report["balanced"]
    with pytest.raises(ConfigError, match="arms"):
        BalanceGains(arms=(40.0, 0.05, -1.0))


def _record_windmill(monkeypatch: pytest.MonkeyPatch, k: int) -> list[float]:
    """Every angle ``BalanceLaw._windmill`` returns for circle ``k`` (0 fore-aft, 1 sideways)."""
    circle: list[float] = []
    windmill = BalanceLaw._windmill

    def spy(law: BalanceLaw, kk: int, *args: float) -> float:
        got = windmill(law, kk, *args)
        if kk == k:
            circle.append(got)
        return got

    monkeypatch.setattr(BalanceLaw, "_windmill", spy)
    return circle


def _on_a_whole_circle(angle: float) -> bool:
    return angle == pytest.approx(2.0 * math.pi * round(angle / (2.0 * math.pi)))


def test_a_forward_push_past_the_toes_is_taken_by_windmilling_arms(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # STANDING_GAINS.windmill: 160 N forward for 0.25 s; the arms circle back and over while the
    # capture point lies past the COM target, finish their circle, and the male stands with his
    # feet down; without them he falls (the limit was 135 N with the bow and arms, 2026-12-03)
    circle = _record_windmill(monkeypatch, 0)
    push = {"check_range": False, "seconds": 3.0, "push": 160.0, "push_dir": 0.0}
    r = run("balance", "male", **push)
    assert r.report["balanced"] and not r.report["fell"]
    after = r.log["t"] >= 0.5
    assert np.count_nonzero(r.log["feet"][after] < 2) <= 10
    assert max(circle) >= 2.0 * math.pi and _on_a_whole_circle(circle[-1])
    no_windmill = dataclasses.replace(STANDING_GAINS, windmill=None)
    monkeypatch.setattr(behaviours, "STANDING_GAINS", no_windmill)
    assert not run("balance", "male", **push).report["balanced"]
    with pytest.raises(ConfigError, match="windmill"):
        BalanceGains(windmill=(8.0, math.nan))


def test_a_sideways_push_is_taken_by_arms_circling_in_the_frontal_plane(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # BalanceGains.windmill_side: 85 N to the female's left for 0.25 s; both arms roll about the
    # fore-aft axis against the fall, finish their circle, and she stands; without them she
    # falls (her limit was 75 N with the sagittal windmill, 2026-12-03)
    circle = _record_windmill(monkeypatch, 1)
    side = dataclasses.replace(STANDING_GAINS, windmill_side=(8.0, 0.05, 0.5))
    monkeypatch.setattr(behaviours, "STANDING_GAINS", side)
    push = {"check_range": False, "seconds": 3.0, "push": 85.0, "push_dir": math.pi / 2}
    r = run("balance", "female", **push)
    assert r.report["balanced"] and not r.report["fell"]
    # a fall to the left rolls the arms about -x; they end on a whole circle
    assert min(circle) <= -2.0 * math.pi and _on_a_whole_circle(circle[-1])
    no_side = dataclasses.replace(STANDING_GAINS, windmill_side=None)
    monkeypatch.setattr(behaviours, "STANDING_GAINS", no_side)
    assert not run("balance", "female", **push).report["balanced"]
    with pytest.raises(ConfigError, match="windmill_side"):
        BalanceGains(windmill_side=(8.0, 0.05, 2.0))


def _drifting(params: dict[str, object]) -> AthleticsResult:
    """A standing male balance started moving back and to the left at 0.3 m/s each: the
    balance phase alone lifts a foot and stands on the other."""
    m = Maneuver("drifting", (Phase("balance", "never", params),), "male", 3.0)
    still = tuple((0.0, 0.0, 0.0) for _ in range(15))
    return run_maneuver(m, perturbation=Perturbation(still, velocity=(-0.3, 0.3, 0.0)), fps=10.0)


def test_a_maneuver_balance_with_the_standing_step_puts_a_hanging_foot_down(
    tmp_path: Path,
) -> None:
    # the file key standing_step (issue 19, 2026-12-05): the balance behaviour's step="on"
    # in a maneuver's balance phase; without it the body ends the run on one foot
    off, on = _drifting({}), _drifting({"standing_step": True})
    last = [np.asarray(r.log["feet"])[np.asarray(r.log["t"]) > 2.0] for r in (off, on)]
    assert not off.report["fell"] and np.mean(last[0] == 1) > 0.9
    assert not on.report["fell"] and np.all(last[1] == 2)
    # a step's numbers override the standing step's, not its plant (a 10 m margin: no step)
    planted = _drifting({"standing_step": True, "step": [10.0]})
    feet = np.asarray(planted.log["feet"])[np.asarray(planted.log["t"]) > 2.0]
    assert not planted.report["fell"] and np.all(feet == 2) and "steps" not in planted.report
    bad = tmp_path / "m.toml"
    bad.write_text('[[phase]]\ncontroller = "balance"\nparams = { standing_step = "on" }\n'
                   'exit = { event = "never" }\n')  # fmt: skip
    with pytest.raises(
        ConfigError, match=r"phase\[1\]\.params\.standing_step must be true or false"
    ) as err:
        load_maneuver(bad)
    assert str(bad) in str(err.value)


def _refused_balance_key(tmp_path: Path, params: str, key: str) -> None:
    """A one-phase balance maneuver file with ``params`` is refused, naming the file and
    ``phase[1].params.<key>``."""
    bad = tmp_path / "m.toml"
    bad.write_text(f'[[phase]]\ncontroller = "balance"\nparams = {{ {params} }}\n'
                   'exit = { event = "never" }\n')  # fmt: skip
    with pytest.raises(ConfigError, match=rf"phase\[1\]\.params\.{key}: needs") as err:
        load_maneuver(bad)
    assert str(bad) in str(err.value)


def test_a_maneuver_balances_hang_near_waits_for_the_com_near_the_sole_to_put_the_foot_down(
    tmp_path: Path,
) -> None:
    # the file key hang_near (issue 19, 2026-12-05): the standing step's plant of a hung foot
    # waits, besides a slow COM, for the COM within this of the standing sole's middle; the
    # forward tuck's plant 9-11 cm off the support kept it on one foot (docs/athletics.md,
    # "Forward tuck: the hung foot put down near the support")
    def one_foot(near: float | None) -> np.ndarray:
        p: dict[str, object] = {"standing_step": True, "step": [10.0]}
        r = _drifting(p if near is None else {**p, "hang_near": near})
        assert not r.report["fell"]
        t, feet = np.asarray(r.log["t"]), np.asarray(r.log["feet"])
        return t[feet == 1]

    default, wide, close = one_foot(None), one_foot(0.05), one_foot(0.005)
    assert default.max() < 1.5 and np.array_equal(wide, default)  # near enough: as before
    assert close.max() > 2.9  # never that near: on one foot to the end
    for params in ("standing_step = true, hang_near = 0.5", "hang_near = 0.05"):
        _refused_balance_key(tmp_path, params, "hang_near")
    with pytest.raises(ConfigError, match="hang_near"):
        Step(hang_near=-0.1)


def test_a_maneuver_balances_plant_settle_is_refused_out_of_range(tmp_path: Path) -> None:
    # the file key plant_settle (issue 19, 2026-12-05): only with standing_step, (0, 5] s
    for params in ("standing_step = true, plant_settle = 6.0", "plant_settle = 1.0",
                   "standing_step = true, plant_settle = 0.0"):  # fmt: skip
        _refused_balance_key(tmp_path, params, "plant_settle")
    for value in (-0.5, 5.5, math.nan):
        with pytest.raises(ConfigError, match="plant_settle"):
            Step(plant_settle=value)


def _pushed_back(step: list[float] | None) -> AthleticsResult:
    """A standing male balance started with the body moving back at 0.5 m/s (its capture
    point past the heels), with the balance's step if given."""
    params = {"step": step} if step is not None else {}
    m = Maneuver("pushed", (Phase("balance", "never", params),), "male", 1.0)
    still = tuple((0.0, 0.0, 0.0) for _ in range(15))
    return run_maneuver(m, perturbation=Perturbation(still, velocity=(-0.5, 0.0, 0.0)), fps=10.0)


def test_a_step_moves_a_foot_toward_the_capture_point_and_off_changes_nothing() -> None:
    stepped = _pushed_back([0.05, 0.1, 0.3, 0.25])
    first = stepped.report["steps"][0]
    # the capture point lies behind: a foot swings from beside the other to well behind it
    assert abs(first["from_m"]) < 0.05 and first["beyond_m"] > 0.05
    assert first["to_m"] < -0.15
    # off (the default), or on with a margin it never passes: the same run to the bit
    off = _pushed_back(None)
    never = _pushed_back([10.0])
    assert "steps" not in off.report and "steps" not in never.report
    np.testing.assert_array_equal(off.log["com"], never.log["com"])
    assert not np.array_equal(off.log["com"], stepped.log["com"])
    with pytest.raises(ConfigError, match="step"):
        Step(margin=-0.1)
    with pytest.raises(ConfigError, match="step"):
        Step.of([0.1, 0.1, 0.3, 0.25, 1.0])


#: step="on" before Step.bow_hold and Step.ground were joined to it (2026-12-05,
#: docs/athletics.md "The standing step's bow held through the swing"): the step the tests
#: below measured their options against
_STEP_BEFORE = dataclasses.replace(balance.STANDING_STEP, ground=0.0, bow_hold=0.0)


def test_a_sideways_push_past_the_feet_is_taken_by_a_balance_step() -> None:
    # the balance behaviour's opt-in step (step="on", balance.STANDING_STEP): 110 N to the
    # female's left for 0.25 s falls with the feet in place (her limit 75 N, 2026-12-03); with
    # the step she steps and stands still on both feet at the end (2026-12-04)
    push = {"check_range": False, "seconds": 3.0, "push": 110.0, "push_dir": math.pi / 2}
    r = run("balance", "female", step="on", **push)
    assert r.report["balanced"] and not r.report["fell"]
    steps = r.report["steps"]
    assert steps and all(s["beyond_m"] > 0.05 for s in steps)
    assert int(r.log["feet"][-1]) == 2 and np.linalg.norm(r.log["com_vel"][-1]) < 0.1
    off = run("balance", "female", **push)
    assert off.report["fell"] and "steps" not in off.report
    with pytest.raises(ConfigError, match="step"):
        run("balance", "female", step="yes", **push)


def test_a_push_kept_standing_on_one_foot_is_reported_as_such(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    # the male's back-left limit without a step (Fig. 7.7, 155 N at 135 deg): still at the
    # end with one foot in the air; ``balanced`` allows that, the report and the CLI say it
    # (on both feet his limit there is 150 N, docs/athletics.md)
    push = {"check_range": False, "seconds": 3.0, "push_dir": math.radians(135.0)}
    r = run("balance", "male", push=155.0, **push).report
    assert r["balanced"] and not r["on_both_feet"]
    assert run("balance", "male", push=150.0, **push).report["on_both_feet"]
    out = tmp_path / "m.bvh"
    args = ["athletics", "balance", "--push", "155", "--push-dir", "135", "--out", str(out)]
    assert main(args) == 0
    assert "on one foot" in capsys.readouterr().out


def test_a_foot_left_hanging_is_put_down_by_the_standing_step(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # step="on" (issue 18, 2026-12-04): the male's 155 N back-left push ends still with one
    # foot in the air and no step taken; once a foot has hung STANDING_HANG s over a COM
    # slower than STANDING_STILL the posture's plant goes on and he ends on both feet
    push = {"check_range": False, "seconds": 3.0, "push": 155.0,
            "push_dir": math.radians(135.0), "step": "on"}  # fmt: skip
    r = run("balance", "male", **push).report
    assert r["balanced"] and r["on_both_feet"] and not r["steps"]
    monkeypatch.setattr(balance, "STANDING_STILL", 0.0)  # the option before: never planted
    never = dataclasses.replace(balance.STANDING_STEP, hang_still=0.0)  # nor before a step
    monkeypatch.setattr(behaviours, "STANDING_STEP", never)
    r = run("balance", "male", **push).report
    assert r["balanced"] and not r["on_both_feet"] and not r["steps"]


def test_a_standing_step_put_past_the_capture_point_across_the_feet_lands(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # issue 18 (2026-12-05, docs/athletics.md "The standing step's first single support"):
    # at the male's 200 N forward push step="on" swings a foot under its own hip that never
    # reaches the floor (the swing runs out at three times its 0.25 s) and he falls; with the
    # foot put 0.15 m past the capture point across the feet (Step.across) it lands within
    # 0.6 s and he is up at 3 s
    push = {"check_range": False, "seconds": 3.0, "push": 200.0, "step": "on"}
    monkeypatch.setattr(behaviours, "STANDING_STEP", _STEP_BEFORE)
    r = run("balance", "male", **push).report
    assert r["fell"] and r["steps"][0]["s"] >= 0.7
    across = dataclasses.replace(_STEP_BEFORE, across=0.15)
    monkeypatch.setattr(behaviours, "STANDING_STEP", across)
    r = run("balance", "male", **push).report
    assert not r["fell"] and r["steps"][0]["s"] < 0.6
    with pytest.raises(ConfigError, match="across"):
        Step(across=-0.1)


def test_a_standing_step_aimed_on_the_floor_from_the_hip_ends_sooner(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # issue 18 (2026-12-05, docs/athletics.md "The standing step's swing shortened"): at the
    # male's 200 N forward push step="on"'s first swing hangs over the floor at STEP_REACH
    # until it runs out (0.75 s); aimed from its middle on at the floor from the hip as it is,
    # with the leg up to 0.99 of straight (Step.ground), the foot lands after about 0.40 s
    # and about as far ahead
    push = {"check_range": False, "seconds": 3.0, "push": 200.0, "step": "on"}
    monkeypatch.setattr(behaviours, "STANDING_STEP", _STEP_BEFORE)
    first = run("balance", "male", **push).report["steps"][0]
    assert first["s"] >= 0.7
    ground = dataclasses.replace(_STEP_BEFORE, ground=0.99)
    monkeypatch.setattr(behaviours, "STANDING_STEP", ground)
    steps = run("balance", "male", **push).report["steps"]
    assert steps[0]["t"] == pytest.approx(first["t"])
    assert steps[0]["s"] < 0.45 and steps[0]["to_m"] > 0.4
    for bad in (0.3, 1.2, -1.0):
        with pytest.raises(ConfigError, match="ground"):
            Step(ground=bad)


def test_a_standing_step_whose_landed_knee_gives_stays_on_both_feet_longer(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # issue 18 (2026-12-05, docs/athletics.md "The standing step's landed knee yields"): at
    # the male's 175 N forward push with Step.ground 0.99 the first step lands at about 2.63 s
    # on a near-straight leg and the rear foot, on its toes, is turned flat off the floor: both
    # feet down about a sixth of the next 0.3 s, and the body hops (COM up at 0.86 m/s); with
    # the landed knee giving 0.3 rad and the rear ankle held (Step.give), about a third,
    # without the hop
    push = {"check_range": False, "seconds": 2.95, "push": 175.0, "step": "on"}
    ground = dataclasses.replace(_STEP_BEFORE, ground=0.99)

    def after_touchdown(step: Step) -> tuple[float, float, float]:
        monkeypatch.setattr(behaviours, "STANDING_STEP", step)
        r = run("balance", "male", **push)
        first = r.report["steps"][0]
        td = first["t"] + first["s"]
        t = r.log["t"]
        w = (t >= td) & (t < td + 0.3)
        up = float(r.log["com_vel"][(t >= td) & (t < td + 0.12), 2].max())
        return td, float(np.mean(r.log["feet"][w] == 2)), up

    td, both, up = after_touchdown(ground)
    assert both < 0.25 and up > 0.5
    td_give, both_give, up_give = after_touchdown(dataclasses.replace(ground, give=0.3))
    assert td_give == pytest.approx(td)
    assert both_give > both + 0.1 and up_give < 0.3
    for field, bad in (("give", -0.1), ("give", 1.5), ("give_time", 0.01), ("give_time", 0.6)):
        with pytest.raises(ConfigError, match=field):
            Step(**{field: bad})  # type: ignore[arg-type]


def test_a_standing_step_placed_at_the_foreseen_capture_point_keeps_the_body_up(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # issue 18 (2026-12-05, docs/athletics.md "The standing step's landed knee yields"): at
    # the male's 200 N forward push, with Step.ground 0.99, give 0.3 and across 0.15, the
    # first step lands past the capture point across the feet as it is at each tick, the COM
    # falls on sideways past the landed foot and he falls by 3 s; with the capture point taken
    # where the COM's sideways speed will have carried it 0.3 s after the swing began
    # (Step.foresee) the same step lands farther out and he does not fall
    push = {"check_range": False, "seconds": 3.0, "push": 200.0, "step": "on"}
    step = dataclasses.replace(_STEP_BEFORE, ground=0.99, give=0.3, across=0.15)
    monkeypatch.setattr(behaviours, "STANDING_STEP", step)
    r = run("balance", "male", **push).report
    assert r["fell"]
    monkeypatch.setattr(behaviours, "STANDING_STEP", dataclasses.replace(step, foresee=0.3))
    r_foresee = run("balance", "male", **push).report
    assert r_foresee["steps"][0]["t"] == pytest.approx(r["steps"][0]["t"])
    assert not r_foresee["fell"]
    with pytest.raises(ConfigError, match="foresee"):
        Step(foresee=0.3)
    with pytest.raises(ConfigError, match="foresee"):
        Step(across=0.15, foresee=1.5)


def test_a_foot_hung_before_the_first_step_is_planted_under_a_faster_com(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # issue 18 (2026-12-05, docs/athletics.md "What follows the standing step's first
    # touchdown"): at the female's 85 N push to her right the standing balance hangs a foot
    # from 1.25 s, the COM slowing to 0.10 m/s, never under STANDING_STILL (0.08), so no plant;
    # the capture point drifts out and the steps that follow leave her moving at 3 s; planted
    # once the COM is slower than 0.25 m/s (Step.hang_still) she stands still on both feet
    # without a step
    # without it (step="on" has it 0.25)
    push = {"check_range": False, "seconds": 3.0, "push": 85.0, "push_dir": -math.pi / 2}
    assert balance.STANDING_STEP.hang_still == 0.25
    step = dataclasses.replace(_STEP_BEFORE, hang_still=0.0)
    monkeypatch.setattr(behaviours, "STANDING_STEP", step)
    r = run("balance", "female", step="on", **push).report
    assert r["steps"] and not (r["balanced"] and r["on_both_feet"])
    monkeypatch.setattr(behaviours, "STANDING_STEP", _STEP_BEFORE)
    r_still = run("balance", "female", step="on", **push).report
    assert not r_still["steps"]
    assert r_still["balanced"] and r_still["on_both_feet"]
    with pytest.raises(ConfigError, match="hang_still"):
        Step(hang_still=-0.1)
    with pytest.raises(ConfigError, match="hang_still"):
        Step(hang_still=float("nan"))


def _her_pushed_back(monkeypatch: pytest.MonkeyPatch, step: Step, newtons: float) -> dict:
    """The female's 3 s standing balance pushed straight back, ``step="on"`` meaning
    ``step``: the run's report."""
    monkeypatch.setattr(behaviours, "STANDING_STEP", step)
    push = {"check_range": False, "seconds": 3.0, "push": newtons, "push_dir": math.pi}
    return run("balance", "female", step="on", **push).report


def test_a_standing_step_whose_bow_is_held_through_the_swing_lands_sooner(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # issue 18 (2026-12-05, docs/athletics.md "The standing step's bow held through the
    # swing"): at the female's 105 N push backward the step fires from a bow; eased out over
    # the gains' 0.15 s as the foot lifts, the pelvis pitching back takes the lagging swing thigh
    # with it, the foot hangs over the floor and the first swing takes >= 0.55 s (planned 0.25)
    # and she falls; with the bow eased out over 1 s during the swing (Step.bow_hold) the same
    # step lands within 0.45 s and she does not fall
    r = _her_pushed_back(monkeypatch, _STEP_BEFORE, 105.0)
    assert r["steps"][0]["s"] >= 0.55 and r["fell"]
    r_held = _her_pushed_back(monkeypatch, dataclasses.replace(_STEP_BEFORE, bow_hold=1.0), 105.0)
    assert r_held["steps"][0]["t"] == r["steps"][0]["t"]
    assert r_held["steps"][0]["s"] < 0.45 and not r_held["fell"]
    for bad in (-0.1, 5.5, float("nan")):
        with pytest.raises(ConfigError, match="bow_hold"):
            Step(bow_hold=bad)


def test_a_standing_steps_next_trigger_on_both_soles_waits_for_the_capture_point(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # issue 18 (2026-12-05, docs/athletics.md "The standing step's bow held through the
    # swing"): at the female's 85 N push backward the rear foot rolls off after the first step
    # and the second fires on the front sole's box alone, the capture point still within 5 cm
    # of both soles' box; judged against both soles' box (Step.pair 0.05) it fires later,
    # with the capture point more than 5 cm past that box
    r = _her_pushed_back(monkeypatch, _STEP_BEFORE, 85.0)
    r_pair = _her_pushed_back(monkeypatch, dataclasses.replace(_STEP_BEFORE, pair=0.05), 85.0)
    assert len(r["steps"]) >= 2 and len(r_pair["steps"]) >= 2
    assert r_pair["steps"][0] == r["steps"][0]
    assert r_pair["steps"][1]["t"] > r["steps"][1]["t"]
    assert r_pair["steps"][1]["beyond_m"] > 0.05
    for bad in (-0.01, 0.31, float("inf")):
        with pytest.raises(ConfigError, match="pair"):
            Step(pair=bad)


def test_the_standing_step_holds_his_175_n_forward_push_with_the_bow_held(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # issue 18 (2026-12-05, docs/athletics.md "The standing step's bow held through the
    # swing"): step="on" with Step.bow_hold 1.0 and Step.ground 0.99 joined: the male's 175 N
    # forward push (his limit before, 170 N) steps once and ends still on both feet; before
    # (neither) the step's swing takes over 0.5 s and he is still moving at 3 s
    push = {"check_range": False, "seconds": 3.0, "push": 175.0, "step": "on"}
    assert balance.STANDING_STEP.bow_hold == 1.0 and balance.STANDING_STEP.ground == 0.99
    r = run("balance", "male", **push).report
    assert len(r["steps"]) == 1 and r["balanced"] and r["on_both_feet"]
    monkeypatch.setattr(behaviours, "STANDING_STEP", _STEP_BEFORE)
    r_before = run("balance", "male", **push).report
    assert r_before["steps"][0]["t"] == r["steps"][0]["t"]
    assert r_before["steps"][0]["s"] > 0.5 and not r_before["balanced"]


def test_the_both_feet_judge_calls_a_one_foot_stand_at_the_end_lost() -> None:
    # her 95 N back-left push: still on one foot at 3 s, down by 5 s (docs/athletics.md, Fig.
    # 7.7 judged at 8 s); feet="both" calls the 3 s run lost, as the 8 s run is; the motion is
    # the same, only the judge differs; 90 N ends on both feet and is held either way
    push = {"check_range": False, "seconds": 3.0, "push_dir": math.radians(135.0)}
    loose = run("balance", "female", push=95.0, **push)
    strict = run("balance", "female", push=95.0, feet="both", **push)
    assert loose.report["balanced"] and not loose.report["on_both_feet"]
    assert not strict.report["balanced"] and not strict.report["on_both_feet"]
    assert np.array_equal(loose.log["com"], strict.log["com"])
    assert run("balance", "female", push=90.0, feet="both", **push).report["balanced"]
    with pytest.raises(ConfigError, match="feet"):
        run("balance", "female", feet="one", **push)

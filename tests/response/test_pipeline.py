"""End-to-end response pipeline on the bundled synthetic clips (and the shared real clips)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from reactmocap.cli import main
from reactmocap.errors import ReactMocapError
from reactmocap.library.bodyparts import map_body_parts
from reactmocap.library.bvh import read_bvh
from reactmocap.metrics import joint_speed_max_m_s
from reactmocap.response import outputs
from reactmocap.response.pipeline import run_response, run_scenario
from reactmocap.response.scenario import (
    AttackerSpec,
    CharacterSpec,
    ImpactSpec,
    ResponseConfig,
    Scenario,
    load_scenario,
)
from reactmocap.rotations import quat_conj, quat_log, quat_mul
from tests.conftest import BEFORE_RIGHT_FALL, REPO, SYNTHETIC, linked_library

EXAMPLES = REPO / "examples"


def push(force: tuple[float, float, float], facing: float = 0.0, **response: float) -> Scenario:
    base = load_scenario(EXAMPLES / "light_push.toml")
    assert base.impact is not None
    return replace(
        base,
        recipient=replace(base.recipient, facing_deg=facing),
        impact=replace(base.impact, force=force),
        response=replace(base.response, **response),
    )


def pelvis_xy(motion, frame: int) -> np.ndarray:  # type: ignore[no-untyped-def]
    parts = map_body_parts(motion.skeleton)
    return motion.global_positions()[frame, parts.joint_of("pelvis"), :2]


def test_zero_impact_oracle() -> None:
    res = run_response(push((0.0, 0.0, 0.0)))
    m = res.matched
    assert m.clip == "guard"
    # the found frame is the recipient's own clip time at the match
    own_time = 0.5 + res.transition_end
    assert abs(m.time - own_time) <= 2.0 / 30.0
    assert m.distance < 0.5
    # the output equals the input motion
    clip = read_bvh(SYNTHETIC / "guard.bvh")
    n = res.recipient.num_frames
    expected = clip.sample(0.5 + np.arange(n) / clip.fps)
    dpos = np.linalg.norm(res.recipient.global_positions() - expected.global_positions(), axis=-1)
    assert dpos.max() < 0.03
    rel = quat_mul(quat_conj(res.recipient.rotations), expected.rotations)
    assert np.linalg.norm(quat_log(rel), axis=-1).max() < 0.15


def test_monotonic_pushes() -> None:
    disp = {}
    for f in (-150.0, -400.0, 400.0):
        res = run_response(push((f, 0.0, 0.0)))
        i = int(round((res.impact_time + 0.6) * res.sim1.fps)) - int(
            round(res.report["impact"]["rewind_time"] * res.sim1.fps)
        )
        start = pelvis_xy(res.sim1, 0)
        disp[f] = pelvis_xy(res.sim1, min(i, res.sim1.num_frames - 1)) - start
    assert abs(disp[-400.0][0]) > abs(disp[-150.0][0])
    assert disp[-400.0][0] < 0 < disp[400.0][0]


def test_exact_landing_and_outputs(tmp_path: Path) -> None:
    scenario = load_scenario(EXAMPLES / "front_kick.toml")
    report = run_scenario(scenario, tmp_path, plot=True)
    for key in ("matched", "candidates", "impact", "timings_s", "quality", "outputs"):
        assert key in report
    for key in ("scan", "sim1", "search", "sim2", "blend", "total"):
        assert report["timings_s"][key] >= 0
    on_disk = json.loads((tmp_path / "report.json").read_text())
    assert on_disk["matched"]["clip"] == report["matched"]["clip"]
    rec = read_bvh(tmp_path / "recipient.bvh")
    att = read_bvh(tmp_path / "attacker.bvh")
    assert (tmp_path / "plot.png").stat().st_size > 1000
    for m in (rec, att):
        assert np.all(np.isfinite(m.global_positions()))
    assert report["quality"]["penetration_max_m"] < 0.1
    # exact landing: at the end of the transition the output is the found clip's pose
    res = run_response(scenario)
    fps = res.recipient.fps
    i_end = int(round(res.transition_end * fps))
    found = res.found.sample([res.matched.time])
    np.testing.assert_allclose(
        res.recipient.global_positions()[i_end], found.global_positions()[0], atol=1e-6
    )


def test_facing_turns_the_outcome() -> None:
    a = run_response(push((-400.0, 0.0, 0.0), facing=0.0))
    b = run_response(push((0.0, -400.0, 0.0), facing=90.0))
    assert a.matched.clip == b.matched.clip
    assert abs(a.matched.time - b.matched.time) < 0.1
    rot = np.array([[0.0, -1.0], [1.0, 0.0]])
    da = pelvis_xy(a.sim1, -1) - pelvis_xy(a.sim1, 0)
    db = pelvis_xy(b.sim1, -1) - pelvis_xy(b.sim1, 0)
    np.testing.assert_allclose(rot @ da, db, atol=0.03)


def test_failing_run_leaves_no_output(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A run that fails late, after the simulation, with its output folder made and one BVH
    file written, leaves no partial files behind."""
    real_write_bvh = outputs.write_bvh
    calls: list[str] = []

    def failing_second_write(motion: Any, path: str | Path, *args: Any, **kwargs: Any) -> Any:
        # the second write whatever the order, so one file is always written before the failure
        calls.append(Path(path).name)
        if len(calls) == 2:
            raise ReactMocapError(f"cannot write {path}: disk full (test)")
        return real_write_bvh(motion, path, *args, **kwargs)

    monkeypatch.setattr(outputs, "write_bvh", failing_second_write)
    out = tmp_path / "out"
    with pytest.raises(ReactMocapError, match="disk full"):
        run_scenario(load_scenario(EXAMPLES / "front_kick.toml"), out)
    assert len(calls) == 2  # the failure came late: after a BVH file was written
    left = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*"))
    assert left in ([], ["out"]), f"partial outputs left behind: {left}"


@pytest.mark.parametrize(
    "path",
    sorted(p for p in EXAMPLES.glob("*.toml") if not p.name.startswith("sweep")),
    ids=lambda p: p.stem,
)
def test_every_example_scenario_runs(path: Path, tmp_path: Path) -> None:
    assert main(["respond", str(path), "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "report.json").read_text())
    assert np.isfinite(report["matched"]["distance"])
    assert read_bvh(tmp_path / "recipient.bvh").num_frames > 10


def test_respond_says_when_nothing_visible_happened(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: a 1 N push printed "reaction 0.00 m (87 deg off the impulse of 0.1 N s)"
    text = (EXAMPLES / "light_push.toml").read_text()
    scenario = tmp_path / "tiny.toml"
    scenario.write_text(
        text.replace('"../data/synthetic_clips"', repr(str(SYNTHETIC)).replace("'", '"')).replace(
            "-250.0", "-1.0"
        )
    )
    assert main(["respond", str(scenario), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["quality"]["reaction_displacement_m"] < 0.01
    assert "no visible reaction (chest 0.0" in out and "deg off the impulse" not in out


def test_demo_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--out", str(tmp_path), "--plot", "--video"]) == 0
    out = capsys.readouterr().out
    assert "recipient" in out and str(tmp_path) in out
    assert (tmp_path / "recipient.bvh").exists()
    import imageio.v3 as iio

    report = json.loads((tmp_path / "report.json").read_text())
    video = Path(report["outputs"]["video"])
    assert video.parent == tmp_path and report["outputs"]["video_renderer"]
    frames = iio.imread(video)
    assert frames.ndim == 4 and frames.shape[0] > 30  # an animation, not a still
    assert frames[0].std() > 1.0  # something was drawn


def test_demo_outside_a_source_checkout_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from reactmocap.commands import response

    monkeypatch.setattr(response, "DEMO_SCENARIO", tmp_path / "examples" / "front_kick.toml")
    assert main(["demo", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "source checkout" in err and "front_kick.toml" in err
    assert not (tmp_path / "out").exists()


def test_real_clips_end_to_end(shared_mocap_dir: Path, tmp_path: Path) -> None:
    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC)
    scenario = Scenario(
        library=lib,
        recipient=CharacterSpec("dataset-1_respond_normal_001", start=0.5),
        attacker=AttackerSpec(
            "dataset-1_kick_normal_001", start=0.0, facing_deg=180.0, position=(0.9, 0.0)
        ),
        name="real",
    )
    report = run_scenario(scenario, tmp_path / "out")
    rec = read_bvh(tmp_path / "out" / "recipient.bvh")
    assert np.all(np.isfinite(rec.global_positions()))
    assert report["quality"]["penetration_max_m"] < 0.15
    names = {f.stem for f in lib.glob("*.bvh")}
    assert report["matched"]["clip"] in names
    # every clip is a candidate continuation: the synthetic ones retargeted onto the recipient
    from reactmocap.response.pipeline import prepare_library

    sub, index = prepare_library(
        lib, read_bvh(shared_mocap_dir / "dataset-1_respond_normal_001.bvh")
    )
    assert set(sub.clips) == names and set(index.clip_names) == names
    real = sub["dataset-1_walk_normal_001"].skeleton
    fall = sub["fall_backward"]
    assert fall.skeleton.same_structure(real)
    assert np.all(np.isfinite(fall.global_positions()))
    assert fall.global_positions()[..., 2].min() > -0.05  # retargeted onto the floor, roughly


def _bench_physical(**kw: Any) -> ResponseConfig:
    """bench_reactions' real recipients: whole-body trackers, the physical mode landing
    within 0.25 m / 0.5 rad in 1 s, three tries."""
    return ResponseConfig(sim1_controller="wholebody", sim2_controller="wholebody",
                          mode="physical", land_position=0.25, land_angle=0.5, land_joint=0.5,
                          land_within=1.0, land_tries=3, **kw)  # fmt: skip


def _bench_kick(shared_mocap_dir: Path, tmp_path: Path, recipient: str, facing_deg: float,
                position: tuple[float, float], mode: str = "physical",
                without: tuple[str, ...] = ()) -> Scenario:  # fmt: skip
    """bench_reactions' real kick at a real recipient (its ``REAL`` settings, in ``mode``)."""
    from dataclasses import replace

    return Scenario(
        library=linked_library(tmp_path, shared_mocap_dir, SYNTHETIC, without=without),
        recipient=CharacterSpec(recipient, start=0.5),
        attacker=AttackerSpec("dataset-1_kick_normal_001", start=0.9333333333333333,
                              facing_deg=facing_deg, position=position),
        response=replace(_bench_physical(attacker_assist=100.0, torque_limit=1000.0), mode=mode),
        name=f"{recipient}-kick",
    )  # fmt: skip


def _real_kick(
    library: Path, recipient: str, facing_deg: float, position: tuple[float, float], name: str
) -> Scenario:
    # bench_reactions' aim: the real front kick at a real recipient, whole-body trackers
    return Scenario(
        library=library,
        recipient=CharacterSpec(recipient, start=0.5),
        attacker=AttackerSpec("dataset-1_kick_normal_001", start=0.9333333333333333,
                              facing_deg=facing_deg, position=position),
        response=ResponseConfig(sim1_controller="wholebody", sim2_controller="wholebody",
                                attacker_assist=100.0),
        name=name,
    )  # fmt: skip


def test_a_blend_held_by_contact_still_moves_the_root_smoothly(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real walk kicked (bench_reactions' aim) falls with its trunk against the kicker to
    # the end of the transition: the blend's root correction (0.5 m) was held to the last
    # frame and jumped there (16.6 m/s); it is now spread over ROOT_BLEND_MIN_S at least (the
    # found clip where the search placed it: moved under the body, ``blend_place``, the
    # correction is 0.05 m)
    from reactmocap.response.final import ROOT_BLEND_MIN_S

    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC, without=BEFORE_RIGHT_FALL)
    scenario = _real_kick(lib, "dataset-1_walk_normal_001", 164.64459363196647,
                          (2.1888065748710512, 0.1540919325202299), "walk-kick")  # fmt: skip
    scenario = replace(scenario, response=replace(scenario.response, blend_place=False))
    res = run_response(scenario)
    offset = res.report["quality"]["blend_root_offset_max_m"]
    assert offset > 0.3  # the case: a large root correction
    out = res.recipient
    pelvis = out.global_positions()[:, res.parts.joint_of("pelvis")]
    speed = np.linalg.norm(np.diff(pelvis, axis=0), axis=1) * out.fps
    # the correction adds at most offset / ROOT_BLEND_MIN_S to the simulated body's own speed
    assert speed.max() < 2.5 + offset / ROOT_BLEND_MIN_S, speed.max()
    assert res.report["quality"]["attacker_speed_ratio"] <= 1.5


def test_the_attacker_blends_back_to_a_spinning_clip_no_faster_than_it(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real walk backwards kicked from behind (bench_reactions' aim, its physical mode):
    # the kick clip spins while the attacker's simulation has stopped, so blending back over
    # the straight-line gap turned the toes 1.61x faster than the capture ever moves them;
    # the blend back is now lengthened until no joint outruns the clip
    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC)
    scenario = Scenario(
        library=lib,
        recipient=CharacterSpec("dataset-1_walk-back_normal_001", start=0.1),
        attacker=AttackerSpec("dataset-1_kick_normal_001", start=1.5833333333333335,
                              facing_deg=372.77788526938275,
                              position=(-1.3014127488540825, -0.2353328567744819)),
        response=_bench_physical(attacker_assist=100.0),
        name="walk-back-kick",
    )  # fmt: skip
    res = run_response(scenario)
    assert res.attacker is not None
    release = res.report["transition"]["end"]  # the attacker is on its own from about here
    out = res.attacker.slice(int(np.ceil(release * res.attacker.fps)))
    clip_speed = joint_speed_max_m_s(read_bvh(next(shared_mocap_dir.glob("*kick_normal_001.bvh"))))
    assert joint_speed_max_m_s(out) <= clip_speed * (1 + 1e-9)
    assert res.report["quality"]["attacker_speed_ratio"] <= 1.5


def test_a_torque_limit_keeps_the_kicked_bow_stable(shared_mocap_dir: Path, tmp_path: Path) -> None:
    # the case below: the whole-body plan asks 41 kN m at a hip before Simulation 1 blows up;
    # with ``torque_limit`` (the plan's feed-forward bounded per joint) it runs to its end
    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC)
    scenario = _real_kick(lib, "dataset-1_bow_normal_001", 167.42333060441473,
                          (0.9101249775269609, 0.24847072154800792), "bow-kick")  # fmt: skip
    scenario = replace(scenario, response=replace(scenario.response, torque_limit=1000.0))
    res = run_response(scenario)
    assert not [w for w in res.report["warnings"] if "stopped early" in w]
    assert res.sim1.duration > 1.3
    assert res.report["quality"]["reaction_displacement_m"] > 0.05


def test_a_search_whose_nearest_windows_are_all_the_own_clip_looks_further(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real bow pushed from behind (bench_reactions' push, physical mode with the torque
    # limit): the 4 nearest windows of every search start are the bow itself, which a real hit
    # rules out; the response failed ("no library window continues the response") and now
    # looks OWN_CLIP_DEPTH windows down each start's ranking
    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC)
    scenario = Scenario(
        library=lib,
        recipient=CharacterSpec("dataset-1_bow_normal_001", start=0.5),
        impact=ImpactSpec("chest", (249.99920660413557, 0.629839108608112, 0.0), 1.0, 0.2),
        response=_bench_physical(torque_limit=1000.0),
        name="bow-push-back",
    )  # fmt: skip
    res = run_response(scenario)
    assert res.matched.clip != "dataset-1_bow_normal_001"
    assert res.report["quality"]["reaction_displacement_m"] > 0.05


def test_a_leg_the_blend_turns_into_the_attacker_is_held_with_the_pelvis(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real walk-right kicked (bench_reactions' aim, physical mode, torque limit): the body
    # did not land (0.6 m, 1.4 rad off), and the blend's turn of the pelvis swung the left
    # shin 6 cm into the kicker while the shin's own joints were held; a leg's overlap now
    # holds the pelvis's turn too, as an arm's holds the trunk's
    scenario = _bench_kick(
        shared_mocap_dir,
        tmp_path,
        "dataset-1_walk-right_normal_001",
        162.95691247341688,
        (2.0136727200528957, 0.0003111082439202495),
        without=BEFORE_RIGHT_FALL,
    )
    res = run_response(scenario)
    assert res.report["quality"]["blend_root_offset_max_m"] > 0.3  # the case: a large correction
    assert res.report["quality"]["character_overlap_max_m"] <= 0.02


@pytest.mark.parametrize(
    ("recipient", "start", "attacker"),
    [
        ("dataset-1_walk-left_normal_001", 0.5,
         AttackerSpec("dataset-1_kick_normal_001", start=0.9333333333333333,
                      facing_deg=171.62535275062777,
                      position=(2.0532632057903535, 0.6267587902974016))),
        ("dataset-1_run_normal_001", 0.1,
         AttackerSpec("dataset-1_kick_normal_001", start=1.6833333333333333,
                      facing_deg=207.03765069334506,
                      position=(1.422719565513337, 0.2043343482184246))),
    ],
    ids=["walk-left", "run"],
)  # fmt: skip
def test_the_kicked_recipients_tail_does_not_run_into_the_attacker(
    shared_mocap_dir: Path, tmp_path: Path, recipient: str, start: float, attacker: AttackerSpec
) -> None:
    # bench_reactions' kicked walk-left and run (physical mode): the found clip's tail walked
    # (11.6 cm) or fell (16.0 cm) onto the attacker its simulation left standing or lying
    # there, and the run's attacker, carried with the recipient's blend, moved 2.29x faster
    # than its clip; it now follows that blend no faster than its clip and steps aside
    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC)
    scenario = Scenario(
        library=lib,
        recipient=CharacterSpec(recipient, start=start),
        attacker=attacker,
        response=_bench_physical(attacker_assist=100.0, torque_limit=1000.0),
        name="kicked",
    )
    res = run_response(scenario)
    q = res.report["quality"]
    assert q["contact_impulse_Ns"] > 50.0  # the case: a real hit
    assert q["character_overlap_max_m"] <= 0.02
    assert q["attacker_speed_ratio"] <= 1.5
    # the attacker stands or lies on the floor: the walk-left's kicker, knocked down, was
    # carried 0.8-1.2 m up by the recipient's blend lifting it off the floor
    body = res.attacker.global_positions()[:, 1:, 2]  # Bandai's joint_Root is on the floor
    assert body.min(axis=1).max() <= 0.3


def test_an_unstable_simulation_2_is_reported_not_fatal_in_the_blend_mode(
    shared_mocap_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # with the trunk's orientation weighted 0.75 the search sends the real walk-right kicked
    # (bench_reactions, blend mode) to a window from which Simulation 2's attacker blows up at
    # 0.99 s; the blend mode raised SimulationError there, the physical mode stopped and warned
    from reactmocap.response import library_cache
    from reactmocap.search.config import SearchWeights

    monkeypatch.setattr(library_cache, "SearchWeights",
                        lambda: SearchWeights(trunk_orientation=0.75))  # fmt: skip
    scenario = _bench_kick(shared_mocap_dir, tmp_path, "dataset-1_walk-right_normal_001",
                           162.95691247341688, (2.0136727200528957, 0.0003111082439202495),
                           mode="blend", without=BEFORE_RIGHT_FALL)  # fmt: skip
    res = run_response(scenario)
    stopped = [w for w in res.report["warnings"] if w.startswith("Simulation 2 stopped early")]
    assert len(stopped) == 1 and "unstable" in stopped[0]
    assert np.all(np.isfinite(res.recipient.global_positions()))
    assert res.attacker is not None and np.all(np.isfinite(res.attacker.global_positions()))


def test_an_unstable_simulation_1_is_reported_not_fatal(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real bow kicked by the real kick (bench_reactions' aim): the whole-body tracker's
    # torques run away in Simulation 1 at 1.2 s; the response stops it there, searches what
    # is left and says so, rather than failing
    from reactmocap.response.stages import UNSTABLE_TRIM_S

    lib = linked_library(tmp_path, shared_mocap_dir, SYNTHETIC)
    scenario = _real_kick(lib, "dataset-1_bow_normal_001", 167.42333060441473,
                          (0.9101249775269609, 0.24847072154800792), "bow-kick")  # fmt: skip
    res = run_response(scenario)
    stopped = [w for w in res.report["warnings"] if w.startswith("Simulation 1 stopped early")]
    assert len(stopped) == 1 and "unstable" in stopped[0]
    assert res.sim1.duration < 1.2 - UNSTABLE_TRIM_S + 1e-6
    assert np.all(np.isfinite(res.recipient.global_positions()))
    assert res.report["quality"]["reaction_displacement_m"] > 0.05

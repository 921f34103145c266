"""The blend mode's landing: ``blend_settle`` lands the final blend where it corrects least
(Simulation 2 runs on along the found clip past the match), and ``land_tries`` tries the
search's next-best windows of other clips when the final blend would warn."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from reactmocap import metrics as qm
from reactmocap.response import stages
from reactmocap.response.pipeline import LibraryCache, run_response
from reactmocap.response.scenario import (
    CharacterSpec,
    ImpactSpec,
    ResponseConfig,
    Scenario,
    load_scenario,
)
from tests.conftest import REPO, SYNTHETIC

EXAMPLES = REPO / "examples"
CACHE = LibraryCache()


def _blend(name: str, **kw: object) -> Scenario:
    sc = load_scenario(EXAMPLES / f"{name}.toml")
    return replace(sc, response=replace(sc.response, mode="blend", **kw))


def _score(report: dict) -> float:
    """The final blend's correction over the warning thresholds (<= 1: no warning)."""
    q = report["quality"]
    return max(q["blend_joint_correction_max_rad"] / qm.WARN_JOINT_CORRECTION_RAD,
               q["blend_root_turn_max_rad"] / qm.WARN_ROOT_TURN_RAD,
               q["blend_root_offset_max_m"] / qm.WARN_ROOT_OFFSET_M)  # fmt: skip


def test_the_blend_mode_settles_where_the_final_blend_corrects_least() -> None:
    # the heavy push's blend at the match turns the root 0.67 rad (over the warning threshold);
    # Simulation 2 runs on, and the blend lands later, where it corrects less (one try: with
    # land_tries the blend at the match switches to fall_backward_fast, which does not warn)
    at_match = run_response(_blend("heavy_push_fall", blend_settle=0.0, land_tries=1), CACHE).report
    settled = run_response(_blend("heavy_push_fall", blend_settle=0.5, land_tries=1), CACHE).report
    tr = settled["transition"]
    assert tr["match"] == at_match["transition"]["match"]  # the same search, the same match
    assert at_match["transition"]["end"] == at_match["transition"]["match"]  # the paper
    assert _score(at_match) > 1.0, at_match["quality"]  # the case: the match's blend warns
    assert tr["match"] < tr["end"] <= tr["match"] + 0.5 + 1e-9
    assert _score(settled) < _score(at_match) - 0.05, (settled["quality"], at_match["quality"])
    assert settled["quality"]["transition_s"] > at_match["quality"]["transition_s"]
    # a settle too short to reach the next candidate frame keeps the match
    short = run_response(_blend("heavy_push_fall", blend_settle=0.01, land_tries=1), CACHE).report
    assert short["transition"]["end"] == short["transition"]["match"]
    assert _score(short) == _score(at_match)


def test_the_blend_mode_lands_at_the_match_when_its_blend_would_not_warn() -> None:
    # the front kick's blend at the match turns 0.43 rad, within the threshold: no later
    # landing is searched, and Simulation 2 stops where it does without blend_settle
    at_match = run_response(_blend("front_kick", blend_settle=0.0), CACHE)
    lazy = run_response(_blend("front_kick", blend_settle=0.5), CACHE)
    assert _score(at_match.report) <= 1.0, at_match.report["quality"]
    tr = lazy.report["transition"]
    assert tr["end"] == tr["match"] == at_match.report["transition"]["end"]
    assert lazy.sim2.num_frames == at_match.sim2.num_frames
    assert _score(lazy.report) == _score(at_match.report)


def test_the_blend_mode_tries_other_clips_when_its_final_blend_would_warn(
    shared_mocap_dir: Path, tmp_path: Path
) -> None:
    # the real walk pushed from the front (bench_reactions' push, blend mode): Simulation 2
    # cannot follow the nearest window (the walk itself, later) closely enough, and the
    # final blend turns the left shin 0.9 rad; another clip's window needs less
    lib = tmp_path / "lib"
    lib.mkdir()
    for f in [*shared_mocap_dir.glob("*.bvh"), *SYNTHETIC.glob("*.bvh")]:
        (lib / f.name).symlink_to(f)
    cfg = ResponseConfig(sim1_controller="wholebody", sim2_controller="wholebody",
                         torque_limit=1000.0, land_tries=1)  # fmt: skip
    sc = Scenario(
        library=lib,
        recipient=CharacterSpec("dataset-1_walk_normal_001", start=0.5),
        impact=ImpactSpec("chest", (-249.73579086797838, 11.49063790854824, 0.0), 1.0, 0.2),
        response=cfg,
        name="walk-push-front",
    )  # fmt: skip
    cache = LibraryCache()
    one = run_response(sc, cache).report
    assert _score(one) > 1.0, one["quality"]  # the case: the nearest window's blend warns
    tries = replace(sc, response=replace(cfg, land_tries=3))
    cast = stages.cast(tries, cache)
    contact = stages.estimate_contact(tries, cast)
    naive = stages.naive_simulation(tries, cast, contact)
    cont = stages.search_continuation(tries, cast, contact, naive)
    others = [c.best.clip for c in cont.alternatives]
    assert cont.best.clip == one["matched"]["clip"]  # the nearest window still comes first
    assert 1 <= len(others) <= 2 and cont.best.clip not in others, others
    three = run_response(tries, cache).report
    assert three["matched"]["clip"] in {cont.best.clip, *others}
    assert _score(three) < _score(one)  # it switched to a continuation it follows closer
    assert three["matched"]["clip"] != one["matched"]["clip"]
    assert three["quality"]["reaction_displacement_m"] > 0.05  # still a reaction

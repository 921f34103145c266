"""Reactions that react: a hit moves the recipient the way it was hit, harder hits move it more,
outputs do not overlap, the attacker moves no faster than its capture, any skeleton works, and
the report says when something is off."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from reactmocap.cli import main
from reactmocap.errors import ConfigError
from reactmocap.library.bodyparts import map_body_parts
from reactmocap.library.bvh import read_bvh
from reactmocap.library.synth import synthetic_clips
from reactmocap.response.pipeline import LibraryCache, run_response
from reactmocap.response.scenario import (
    AttackerSpec,
    CharacterSpec,
    load_scenario,
    parse_scenario,
)
from reactmocap.sim.bodies import SIM_BODIES
from tests.conftest import REPO, SYNTHETIC, linked_library
from tests.fixtures.one_spine import dummy_root, write_one_spine

EXAMPLES = REPO / "examples"
CACHE = LibraryCache()


def _report(name: str) -> dict:  # type: ignore[type-arg]
    return run_response(load_scenario(EXAMPLES / f"{name}.toml"), CACHE).report


def test_the_front_kick_moves_the_recipient_the_way_it_was_hit_from_8_directions() -> None:
    from reactmocap.batch import load_sweep

    base = load_sweep(EXAMPLES / "sweep_facing.toml").points()[0].scenario  # the aimed kick
    good = own = 0
    for deg in range(0, 360, 45):
        sc = replace(base, recipient=replace(base.recipient, facing_deg=float(deg)))
        q = run_response(sc, CACHE).report
        qual = q["quality"]
        good += qual["reaction_displacement_m"] >= 0.10 and (
            qual["reaction_direction_error_deg"] <= 45.0
        )
        own += q["matched"]["clip"] == "guard"
    assert good == 8, good
    assert own == 0


def test_the_reaction_grows_with_the_impulse_and_heavy_pushes_fall() -> None:
    light, medium, heavy = (_report(n) for n in ("light_push", "medium_push", "heavy_push_fall"))
    d = [r["quality"]["reaction_displacement_m"] for r in (light, medium, heavy)]
    assert d[0] < d[1] < d[2], d
    assert light["quality"]["reaction_displacement_m"] >= 0.10
    assert not light["quality"]["fell"]
    assert heavy["quality"]["fell"] and heavy["quality"]["intended_fall"]
    # the active response shows: the transition outlasts the reaction delay by far
    assert light["quality"]["transition_s"] >= 0.35
    impulse = np.asarray(light["impact"]["impulse_Ns"])
    assert light["quality"]["contact_impulse_Ns"] == pytest.approx(np.linalg.norm(impulse))


def test_strikes_peak_like_human_strikes_and_attackers_move_like_their_clips() -> None:
    for name in ("front_kick", "punch", "side_kick_chest"):
        rep = _report(name)
        assert 1000.0 <= rep["impact"]["peak_force_N"] <= 6000.0, (name, rep["impact"])
        assert rep["quality"]["contact_impulse_Ns"] > 10.0
        assert rep["quality"]["attacker_speed_ratio"] <= 1.5
        assert rep["quality"]["character_overlap_max_m"] <= 0.02


def test_no_overlap_when_the_recipient_walks_into_a_kick() -> None:
    base = load_scenario(EXAMPLES / "front_kick.toml")
    sc = replace(base, recipient=CharacterSpec("step_forward", 0.0, 0.0, (0.0, 0.0)),
                 attacker=AttackerSpec("front_kick", 0.0, 180.0, (1.1, 0.0)))  # fmt: skip
    res = run_response(sc, CACHE)
    q = res.report["quality"]
    assert q["contact_impulse_Ns"] > 20.0  # a real hit
    assert q["character_overlap_max_m"] <= 0.02
    assert q["attacker_speed_ratio"] <= 1.5


def test_strict_exits_non_zero_on_warnings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    far = tmp_path / "miss.toml"
    far.write_text(
        f'library = "{SYNTHETIC}"\n[recipient]\nclip = "guard"\nstart = 0.5\n'
        '[attacker]\nclip = "front_kick"\nfacing_deg = 180\nposition = [2.5, 0.0]\n'
    )
    assert main(["respond", str(far), "--out", str(tmp_path / "a")]) == 0
    assert "warning: the attacker never touched" in capsys.readouterr().out
    assert main(["respond", str(far), "--out", str(tmp_path / "b"), "--strict"]) == 3
    report = json.loads((tmp_path / "b" / "report.json").read_text())
    assert any("never touched" in w for w in report["warnings"])


def test_one_spine_skeleton_as_recipient_attacker_and_in_a_library(tmp_path: Path) -> None:
    clips = synthetic_clips(60.0)
    lib = linked_library(tmp_path, SYNTHETIC)
    write_one_spine(clips["guard"], lib / "cmu_guard.bvh")
    write_one_spine(clips["front_kick"], lib / "cmu_kick.bvh")
    m = read_bvh(lib / "cmu_guard.bvh")
    parts = map_body_parts(m.skeleton)
    assert parts.joint_of("waist") == parts.joint_of("chest")  # one spine joint, shared
    assert m.fps == 120.0 and m.skeleton.layout.unit == "in"
    sc = parse_scenario({
        "library": str(lib),
        "recipient": {"clip": "cmu_guard", "start": 0.5},
        "attacker": {"clip": "cmu_kick", "facing_deg": 180, "position": [0.9, 0.0]},
    }, source="one_spine")  # fmt: skip
    res = run_response(sc, LibraryCache())
    q = res.report["quality"]
    assert res.recipient.skeleton.same_structure(m.skeleton)
    assert q["contact_impulse_Ns"] > 10.0 and q["reaction_displacement_m"] > 0.05
    assert np.isfinite(res.recipient.global_positions()).all()
    assert res.report["library_skipped"] == []
    # and in a library that a standard recipient searches (retargeted): mapped, not skipped
    std = run_response(load_scenario(EXAMPLES / "light_push.toml").with_changes(library=lib),
                       LibraryCache())  # fmt: skip
    assert std.report["library_skipped"] == []


def test_an_unmappable_or_corrupt_clip_is_skipped_and_named(tmp_path: Path) -> None:
    lib = linked_library(tmp_path, SYNTHETIC)
    text = (SYNTHETIC / "sway.bvh").read_text().replace("LeftUpLeg", "Thing7")
    (lib / "odd.bvh").write_text(text)
    (lib / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    sc = load_scenario(EXAMPLES / "light_push.toml").with_changes(library=lib)
    rep = run_response(sc, LibraryCache()).report
    skipped = {Path(s["clip"]).name: s["reason"] for s in rep["library_skipped"]}
    assert set(skipped) == {"odd.bvh", "broken.bvh"}
    assert "l_thigh" in skipped["odd.bvh"]


def test_a_dummy_root_rides_under_the_pelvis_and_never_jumps(tmp_path: Path) -> None:
    clips = synthetic_clips(60.0)
    lib = tmp_path / "lib"
    lib.mkdir()
    from reactmocap.library.bvh import write_bvh

    for name in ("guard", "step_back", "step_back_1", "step_back_2", "sway", "fall_backward"):
        write_bvh(dummy_root(clips[name]), lib / f"{name}.bvh")
    sc = load_scenario(EXAMPLES / "medium_push.toml").with_changes(library=lib)
    res = run_response(sc, LibraryCache())
    out = res.recipient
    parts = map_body_parts(out.skeleton)
    g = out.global_positions()
    root, pelvis = g[:, 0], g[:, parts.joint_of("pelvis")]
    assert np.allclose(root[:, :2], pelvis[:, :2], atol=1e-9) and np.allclose(root[:, 2], 0.0)
    step = np.linalg.norm(np.diff(root, axis=0), axis=1) * out.fps
    assert step.max() < 4.0, step.max()  # m/s: the root follows the body, no jumps


def test_bad_inputs_get_clear_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(ConfigError, match=r"\[impact\].*physical limit"):
        parse_scenario({"library": str(SYNTHETIC), "recipient": {"clip": "guard"},
                        "impact": {"force": [0.0, 0.0, 30000.0]}}, source="strong")  # fmt: skip
    src = SYNTHETIC / "guard.bvh"
    for fps in ("0", "-5"):
        out = tmp_path / f"g{fps}.bvh"
        assert main(["convert", str(src), str(out), "--fps", fps]) == 2
        assert not out.exists()
    (tmp_path / "empty").mkdir()
    assert main(["library", "check", str(tmp_path / "empty")]) != 0
    assert "no .bvh files" in capsys.readouterr().out
    # a clip path is looked up beside the scenario first
    (tmp_path / "sc").mkdir()
    (tmp_path / "sc" / "mine.bvh").write_text((SYNTHETIC / "guard.bvh").read_text())
    sc = parse_scenario({"library": str(SYNTHETIC), "recipient": {"clip": "mine.bvh"},
                         "impact": {}}, source=str(tmp_path / "sc" / "x.toml"),
                        base_dir=tmp_path / "sc")  # fmt: skip
    assert run_response(sc, CACHE).recipient.num_frames > 10
    missing = sc.with_changes(recipient=CharacterSpec("nowhere.bvh"))
    with pytest.raises(ConfigError, match="nowhere.bvh"):
        run_response(missing, CACHE)


def test_simulation_2_lowers_the_friction_of_the_limbs_only() -> None:
    # the paper lowers Simulation 2's friction "to allow foot slippage"; lowered on the trunk
    # too, the heavy push's fallen body slid on along the floor 0.28 m past where Simulation
    # 1's lay (where the search placed the found clip) and the final blend moved the root 0.31 m
    from reactmocap import metrics as qm
    from reactmocap.response import stages

    sc = load_scenario(EXAMPLES / "heavy_push_fall.toml")
    cfg = sc.response
    cast = stages.cast(sc, CACHE)
    world = stages._world(cast, cfg, cfg.friction_sim2)
    mu = world.model.geom_friction[:, 0]
    own = world.characters[0].geom_ids
    limbs = np.isin(world.geom_body[own], [SIM_BODIES.index(b) for b in stages.LIMBS])
    assert limbs.any() and (~limbs).any()
    assert np.all(mu[own[limbs]] == cfg.friction_sim2)
    assert np.all(mu[own[~limbs]] == cfg.friction_sim1)
    with pytest.raises(ConfigError, match="bodies"):
        world.set_friction(0.5, character=0, bodies=("l_paw",))
    contact = stages.estimate_contact(sc, cast)
    naive = stages.naive_simulation(sc, cast, contact)
    cont = stages.search_continuation(sc, cast, contact, naive)
    sim2 = stages.transition_simulation(sc, cast, contact, naive, cont)
    pelvis = cast.recipient.parts.joint_of("pelvis")
    at = [cont.time - contact.rewind]
    lay = [m.sample(at).global_positions()[0, pelvis, :2] for m in (naive.motion, sim2.motion)]
    assert naive.motion.sample(at).global_positions()[0, pelvis, 2] < 0.3  # lying: the case
    assert np.linalg.norm(lay[0] - lay[1]) < 0.15, lay  # 0.28 m on the lowered whole body
    report = run_response(sc, CACHE).report
    assert report["quality"]["blend_root_offset_max_m"] <= qm.WARN_ROOT_OFFSET_M
    assert report["warnings"] == []


def test_simulation_2_fills_the_joints_it_does_not_simulate_from_what_it_was_asked() -> None:
    # the head, clavicles and toes are not simulated: in Simulation 2's output they follow the
    # desired motion (eased into the found clip), not the old clip, so the final blend corrects
    # only what the physics did not follow
    from reactmocap.response import final, stages

    # a found clip whose head and toes end away from the old clip's (the medium push's
    # step_back_2 ends with them as the old clip holds them, so the test could not fail there)
    sc = load_scenario(EXAMPLES / "heavy_push_fall.toml")
    cast = stages.cast(sc, CACHE)
    contact = stages.estimate_contact(sc, cast)
    naive = stages.naive_simulation(sc, cast, contact)
    cont = stages.search_continuation(sc, cast, contact, naive)
    sim2 = stages.transition_simulation(sc, cast, contact, naive, cont)
    out = final.blend(sc, cast, contact, naive, cont, sim2)
    rec = cast.recipient
    anchors = {int(a) for a in rec.character.anchors}
    free = [j for j in range(1, rec.motion.num_joints) if j not in anchors]
    assert free  # the synthetic skeleton has head, clavicles and toes
    fps = rec.motion.fps
    times = np.arange(round(naive.impact_time * fps), round(cont.time * fps) + 1) / fps
    asked = stages.desired_motion(cast, sc.response, times, naive.impact_time,
                                  stages.yields_to(sc.response, naive.impulse), cont)  # fmt: skip
    got = sim2.motion.sample(times - contact.rewind)
    dot = np.abs(np.sum(got.rotations[:, free] * asked.rotations[:, free], axis=-1))
    assert dot.min() > 1 - 1e-6
    old = rec.motion.sample(times + rec.clock0)
    moved = np.abs(np.sum(old.rotations[-1, free] * asked.rotations[-1, free], axis=-1))
    assert moved.min() < 0.999  # the old clip's would differ: the test can fail
    # and the final blend leaves them as asked
    rel = np.abs(np.sum(out.simulated.rotations[:, free] * out.blended.rotations[:, free], -1))
    assert rel.min() > 1 - 1e-6


def test_the_retargeted_library_does_not_depend_on_the_recipient_before(tmp_path: Path) -> None:
    # two recipients on one skeleton, posed differently at frame 0 (which sets the anatomical
    # frames of a retargeting onto them): the second must get the library retargeted for
    # itself, as it does alone, not the first one's from the shared cache
    from reactmocap.response.pipeline import prepare_library
    from tests.fixtures.one_spine import one_spine

    clips = synthetic_clips(60.0)
    lib = tmp_path / "lib"
    lib.mkdir()
    for name in ("guard", "fall_backward"):
        (lib / f"{name}.bvh").symlink_to(SYNTHETIC / f"{name}.bvh")
    first = one_spine(clips["guard"])
    kick = one_spine(clips["front_kick"])
    second = kick.slice(kick.num_frames // 2, None)  # mid-kick at its frame 0
    assert first.skeleton == second.skeleton
    shared = LibraryCache()
    before, _ = prepare_library(lib, first, cache=shared)
    after, index = prepare_library(lib, second, cache=shared)
    alone, _ = prepare_library(lib, second, cache=LibraryCache())
    fall = [m["fall_backward"].rotations for m in (before, after, alone)]
    assert not np.allclose(fall[0], fall[2], atol=1e-3)  # the two recipients' retargets differ
    np.testing.assert_array_equal(fall[1], fall[2])
    assert index is not prepare_library(lib, first, cache=shared)[1]

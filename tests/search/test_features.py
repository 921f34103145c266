"""Window features: heading, alignment, sign-safe orientation distance, support body, registry."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.library.motion import Motion
from reactmocap.rotations import quat_exp, quat_mul
from reactmocap.search import (
    FEATURE_SETS,
    MotionIndex,
    SearchWeights,
    WindowConfig,
    get_feature_set,
)
from reactmocap.search.distance import localize, select_support
from reactmocap.search.features import calibrate, frame_features
from reactmocap.search.query import distances


def test_heading_of_synthetic_clips_starts_at_zero(synth_clips: dict[str, Motion]) -> None:
    # the synthetic clips start at the origin facing +X (heading 0)
    fs = get_feature_set("paper")
    for name, m in synth_clips.items():
        ff = frame_features(m, calibrate(m.skeleton, fs))
        assert abs(ff.heading[0]) < np.radians(10), name


def test_heading_follows_yaw_and_local_features_are_invariant(
    synth_clips: dict[str, Motion],
) -> None:
    m = synth_clips["front_kick"]
    cal = calibrate(m.skeleton, get_feature_set("paper"))
    a = frame_features(m, cal)
    yaw, shift = 2.5, np.array([3.0, -7.0])
    b = frame_features(m.transformed(yaw, shift), cal)
    dh = (b.heading - a.heading - yaw + np.pi) % (2 * np.pi) - np.pi
    assert np.max(np.abs(dh)) < 1e-9
    c, s = np.cos(yaw), np.sin(yaw)
    np.testing.assert_allclose(b.origin, a.origin @ np.array([[c, s], [-s, c]]) + shift, atol=1e-9)
    la = localize(a.positions[None], a.orientations[None], a.heading[:1], a.origin[:1])
    lb = localize(b.positions[None], b.orientations[None], b.heading[:1], b.origin[:1])
    np.testing.assert_allclose(la[0], lb[0], atol=1e-9)
    # orientations may differ by sign only
    dots = np.abs(np.sum(la[1] * lb[1], axis=-1))
    np.testing.assert_allclose(dots, 1.0, atol=1e-9)


def test_heading_ignores_height_and_tilt(synth_clips: dict[str, Motion]) -> None:
    # lifting the character and pitching the pelvis 60 degrees forward keeps its heading
    m = synth_clips["guard"].slice(0, 5)
    cal = calibrate(m.skeleton, get_feature_set("paper"))
    base = frame_features(m, cal)
    pitch = quat_exp(np.array([0.0, np.radians(60), 0.0]))  # about +Y (left, at heading 0)
    rot = np.array(m.rotations)
    rot[:, 0] = quat_mul(pitch, rot[:, 0])
    tilted = frame_features(
        m.replace(rotations=rot, root_positions=m.root_positions + np.array([0, 0, 0.5])), cal
    )
    np.testing.assert_allclose(tilted.heading, base.heading, atol=1e-6)


def test_body_frame_is_right_handed_including_mirror(synth_clips: dict[str, Motion]) -> None:
    fs = get_feature_set("paper")
    li, ri = fs.parts.index("l_thigh"), fs.parts.index("r_thigh")
    hi = fs.parts.index("head")
    for m in (synth_clips["guard"], synth_clips["guard"].mirror()):
        ff = frame_features(m, calibrate(m.skeleton, fs))
        lp, _ = localize(ff.positions[None], ff.orientations[None], ff.heading[:1], ff.origin[:1])
        assert lp[0, 0, li, 1] > lp[0, 0, ri, 1] + 0.05  # left thigh on +Y in the local frame
        assert lp[0, 0, hi, 2] > 1.3  # height kept


def test_orientation_distance_is_sign_safe_and_equals_chordal_angle(
    synth_index: MotionIndex, synth_clips: dict[str, Motion]
) -> None:
    m = synth_clips["punch"]
    flipped = m.replace(rotations=-np.asarray(m.rotations))  # same rotations, opposite signs
    r = synth_index.window_distance(flipped, 10, "punch", 5)
    assert r.distance < 1e-6
    # one body turned by phi: its orientation term is w * 2 sin(phi / 2)
    qw = synth_index.prepare_query(m, 10)
    phi = 0.7
    turn = np.array([np.cos(phi / 2), 0.0, 0.0, np.sin(phi / 2)], dtype=np.float32)
    b = get_feature_set("paper").parts.index("chest")
    ori = np.array(qw.orientations)
    ori[:, b] = quat_mul(ori[:, b], turn).astype(np.float32)
    from dataclasses import replace

    q2 = replace(qw, orientations=ori)
    start = np.array([synth_index.clip_offsets[synth_index.clip_index("punch")] + 5])
    d0, _ = distances(synth_index, qw, start)
    d1, br = distances(synth_index, q2, start, breakdown=True)
    expect = SearchWeights().trunk_orientation * 2 * np.sin(phi / 2)
    assert d0[0] < 1e-6
    assert d1[0] == pytest.approx(expect, rel=1e-4)
    assert br[0, 1] == pytest.approx(expect, rel=1e-4)  # all in trunk_orientation


def test_support_body_selection() -> None:
    fs = get_feature_set("paper")
    w = SearchWeights()
    p = np.zeros((len(fs.parts), 3))
    idx = {name: i for i, name in enumerate(fs.parts)}
    p[:, 2] = 1.0
    p[idx["l_foot"]] = (0.1, 0.1, 0.05)
    p[idx["r_foot"]] = (-0.4, -0.1, 0.05)
    p[idx["l_hand"]] = (0.0, 0.0, 0.9)
    com = np.array([0.05, 0.05, 0.9])
    assert fs.parts[select_support(p, com, fs, w)] == "l_foot"
    # a fallen character: the hand on the floor right under the centre of mass wins
    p[idx["l_hand"]] = (0.04, 0.05, 0.06)
    assert fs.parts[select_support(p, com, fs, w)] == "l_hand"
    # the same hand a metre up does not count as support
    p[idx["l_hand"], 2] = 1.0
    assert fs.parts[select_support(p, com, fs, w)] == "l_foot"


def test_registry_and_config_validation() -> None:
    assert "paper" in FEATURE_SETS
    with pytest.raises(UnknownKeyError, match="paper"):
        SearchWeights(feature_set="nope")
    with pytest.raises(ConfigError, match="trunk_position"):
        SearchWeights(trunk_position=-1.0)
    with pytest.raises(ConfigError, match="fps"):
        WindowConfig(fps=0)
    with pytest.raises(ConfigError, match="unknown fields"):
        WindowConfig.from_dict({"fps": 30, "bogus": 1})
    w = SearchWeights().window_weights(10)
    assert w.sum() == pytest.approx(1.0)
    assert np.all(np.diff(w) < 0)  # highest at the first frame, decreasing
    assert WindowConfig(fps=30, duration=0.3).length == 10
    assert WindowConfig(fps=120, duration=0.3).length == 37


def test_heading_of_real_clips_follows_walking_direction(real_clips: dict[str, Motion]) -> None:
    """Bandai Namco skeleton (rest pose lying along +X, a dummy root joint): the heading of a
    forward walk matches its direction of travel, and of a backward walk the opposite one."""
    fs = get_feature_set("paper")
    for name, sign in (
        ("walk_normal_001", 1.0),
        ("walk-back_normal_001", -1.0),
        ("run_normal_001", 1.0),
    ):
        m = next(v for k, v in real_clips.items() if k.endswith(name))
        ff = frame_features(m, calibrate(m.skeleton, fs))
        travel = sign * (ff.origin[-1] - ff.origin[0])
        mean_heading = np.angle(np.mean(np.exp(1j * ff.heading)))
        diff = np.angle(np.exp(1j * (mean_heading - np.arctan2(travel[1], travel[0]))))
        assert abs(diff) < np.radians(20), (name, np.degrees(diff))
        assert abs(np.degrees(ff.heading[0]) + 90) < 30  # the files face -Y in our Z-up world

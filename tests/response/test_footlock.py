"""Foot locking: sliding planted feet get pinned, the ends of the transition stay exact, and a
motion without skate is left alone."""

from __future__ import annotations

import numpy as np
import pytest

from reactmocap.errors import ConfigError
from reactmocap.library.bodyparts import map_body_parts
from reactmocap.library.motion import Motion
from reactmocap.library.synth import synthetic_clips
from reactmocap.metrics import foot_skate_m
from reactmocap.response.footlock import END_EASE_FRAMES, lock_feet
from reactmocap.response.scenario import parse_scenario


@pytest.fixture(scope="module")
def guard() -> Motion:
    return synthetic_clips(30.0)["guard"].slice(0, 40)


def test_no_skate_no_change(guard: Motion) -> None:
    parts = map_body_parts(guard.skeleton)
    assert foot_skate_m(guard, parts) < 0.02
    out = lock_feet(guard, parts)
    np.testing.assert_array_equal(out.global_positions(), guard.global_positions())


def test_sliding_feet_are_pinned_and_ends_kept(guard: Motion) -> None:
    parts = map_body_parts(guard.skeleton)
    # the whole body glides 12 cm sideways over the clip, as a root-offset blend does
    n = guard.num_frames
    drift = np.linspace(0.0, 0.12, n)[:, None] * np.array([0.0, 1.0, 0.0])
    slid = guard.replace(root_positions=np.asarray(guard.root_positions) + drift)
    before = foot_skate_m(slid, parts)
    out = lock_feet(slid, parts)
    after = foot_skate_m(out, parts)
    assert before > 0.15 and after < 0.25 * before, (before, after)
    g0, g1 = slid.global_positions(), out.global_positions()
    np.testing.assert_allclose(g1[[0, -1]], g0[[0, -1]], atol=1e-12)
    # only the legs move (the pelvis path is untouched), by no more than the slide
    np.testing.assert_allclose(g1[:, parts.joint_of("pelvis")], g0[:, parts.joint_of("pelvis")])
    assert np.abs(g1 - g0).max() < 0.13
    # away from the eased ends, the planted ankles stay put horizontally
    e = END_EASE_FRAMES
    for s in "lr":
        a = g1[:, parts.joint_of(f"{s}_foot"), :2]
        assert np.linalg.norm(a[e:-e] - a[-1], axis=-1).max() < 0.01


def test_foot_lock_option_is_validated() -> None:
    base = {"library": "data/synthetic_clips", "recipient": {"clip": "guard"},
            "impact": {"body": "chest", "force": [-300, 0, 0], "at": 0.5}}  # fmt: skip
    sc = parse_scenario({**base, "response": {"foot_lock": False}})
    assert sc.response.foot_lock is False
    with pytest.raises(ConfigError, match=r"\[response\]\.foot_lock"):
        parse_scenario({**base, "response": {"foot_lock": "yes"}})

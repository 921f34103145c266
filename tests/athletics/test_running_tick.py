"""The running controller's per-tick shortcuts give the plain forms' values to the bit."""

from __future__ import annotations

import numpy as np

from reactmocap.athletics.balance import knee_for_length, knee_for_length1


def test_knee_for_length1_equals_knee_for_length_to_the_bit() -> None:
    # the runner's one-leg float form against the array form: lengths inside and outside the
    # reachable range (both clips), numpy scalars and floats as the runner passes them
    rng = np.random.default_rng(7)
    thighs, shins = rng.uniform(0.3, 0.5, (2, 3000))
    lengths = np.where(np.arange(3000) % 3 == 0, rng.uniform(-0.1, 1.1, 3000),
                       rng.uniform(0.5, 1.0, 3000) * (thighs + shins))  # fmt: skip
    for ul, ll, length in zip(thighs, shins, lengths):
        plain = knee_for_length(ul, ll, length)
        fast = np.array(knee_for_length1(ul, ll, length))
        assert plain.tobytes() == fast.tobytes(), (ul, ll, length)


def test_the_tick_rotations_equal_the_plain_forms_to_the_bit() -> None:
    # a short real run: the tick's pitches from the rotations made once (_leg_pitches'
    # buffers, the parents' conjugates in one product) against _pitch / _joint_pitch
    from reactmocap.athletics.run_course import run_course
    from reactmocap.athletics.running_body import LEG_JOINTS, SHIN, THIGH
    from reactmocap.sim.bodies import SIM_BODY_INDEX

    r = run_course(3.5, seconds=0.6, fps=10.0).runner
    angles = r._leg_pitches()
    for j in LEG_JOINTS:
        assert angles[j, 0] == r._joint_pitch(j)
    bodies = [(r._root, 0), (r._chest, SIM_BODY_INDEX["chest"])]
    bodies += [(r._thighs[k], THIGH[k]) for k in range(2)]
    bodies += [(r._shins[k], SHIN[k]) for k in range(2)]
    for heading in (r.heading_d, r.heading(), 0.0, -0.0, 0.3):
        for body, neutral in bodies:
            plain, tick = r._pitch(body, neutral, heading), r._tick_pitch(body, heading)
            assert np.float64(plain).tobytes() == np.float64(tick).tobytes()


def test_closest_on_one_segment_equals_the_array_search_to_the_bit() -> None:
    # the straight line's window is one segment: the float search against the arrays' (the
    # window search's own expressions), points on, off and behind the segment
    from reactmocap.athletics.paths import Straight
    from reactmocap.rotations import einsum

    rng = np.random.default_rng(11)
    for heading in (0.0, 0.7, -2.9):
        line = Straight(heading, rng.normal(size=2) * 10.0)
        a, sv, len2 = line.points[:1], line.seg[:1], line.len[:1] ** 2
        pts = rng.normal(size=(500, 2)) * np.array([[1e4], [1.0]]).repeat(250, 0)
        pts[::50] = line.points[0]
        for p in pts:
            u = np.minimum(np.maximum(einsum("ij,ij->i", p - a, sv) / len2, 0.0), 1.0)
            q = a + u[:, None] * sv
            dist = np.hypot(*(p - q).T)
            side = float(np.sign(sv[0, 0] * (p[1] - q[0, 1]) - sv[0, 1] * (p[0] - q[0, 0])))
            want = (0, line._cum[0] + float(u[0]) * line._len[0], side * float(dist[0]))
            got = line._closest(p)
            assert np.array(got).tobytes() == np.array(want).tobytes(), (heading, p)

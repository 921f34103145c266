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

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

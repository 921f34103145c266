"""Deva-style spline control functions (seed 003, section 3)."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.sim.control_functions import ControlFunction, ControlFunctionSet

KNEE = ([0.0, 0.2, 0.5, 0.9], [0.1, 1.2, 0.4, 0.0])
HIP = ([0.1, 0.3, 0.6], [-0.3, 0.5, 0.2])
ELBOW = ([0.0, 1.0], [0.0, 2.0])  # two points: a straight line


def _set() -> ControlFunctionSet:
    return ControlFunctionSet(
        {
            "knee": KNEE,
            "hip": ControlFunction(*HIP, bc_type="clamped"),
            "elbow": ELBOW,
        },
        kind="angle",
    )


def test_passes_through_control_points_and_matches_scipy() -> None:
    f = ControlFunction(*KNEE)
    np.testing.assert_allclose(f(KNEE[0]), KNEE[1], atol=1e-12)
    ts = np.linspace(0.0, 0.9, 37)
    np.testing.assert_allclose(f(ts), CubicSpline(*KNEE)(ts), atol=1e-12)
    assert float(f(0.35)) != pytest.approx(np.interp(0.35, *KNEE))  # a cubic, not linear


def test_set_agrees_with_each_curve_everywhere() -> None:
    cs = _set()
    out = np.empty(3)
    dout = np.empty(3)
    for t in np.concatenate([np.linspace(-0.5, 1.5, 161), [0.0, 0.1, 0.3, 0.6, 0.9, 1.0]]):
        got = cs.evaluate(float(t), out=out)
        assert got is out
        want = [float(cs[n](t)) for n in cs.names]
        np.testing.assert_allclose(out, want, atol=1e-12, err_msg=f"t={t}")
        cs.derivative(float(t), out=dout)
        want_d = [float(cs[n].derivative(t)) for n in cs.names]
        np.testing.assert_allclose(dout, want_d, atol=1e-10, err_msg=f"t={t}")
    np.testing.assert_allclose(cs.evaluate(0.5), [0.4, float(cs["hip"](0.5)), 1.0], atol=1e-12)


def test_derivative_matches_finite_differences() -> None:
    cs = _set()
    h = 1e-6
    for t in np.linspace(0.01, 0.89, 45):
        fd = (cs.evaluate(t + h) - cs.evaluate(t - h)) / (2 * h)
        # the hip curve starts at 0.1 and ends at 0.6: skip its kinks
        if abs(t - 0.1) < 2 * h or abs(t - 0.6) < 2 * h:
            continue
        np.testing.assert_allclose(cs.derivative(t), fd, atol=1e-5, err_msg=f"t={t}")
    assert ControlFunction(*ELBOW).derivative(0.5) == pytest.approx(2.0)


def test_holds_end_values_outside_the_range() -> None:
    f = ControlFunction(*KNEE)
    assert float(f(-3.0)) == 0.1 and float(f(0.0)) == pytest.approx(0.1)
    assert float(f(7.0)) == 0.0
    assert float(f.derivative(-1.0)) == 0.0 and float(f.derivative(2.0)) == 0.0
    assert float(f.derivative(0.9)) == 0.0  # right-continuous: t_end is held
    assert float(f.derivative(0.0)) != 0.0  # not-a-knot end slope
    cs = _set()
    np.testing.assert_allclose(cs.evaluate(-1.0), [0.1, -0.3, 0.0])
    np.testing.assert_allclose(cs.evaluate(5.0), [0.0, 0.2, 2.0])
    np.testing.assert_allclose(cs.derivative(5.0), 0.0)
    np.testing.assert_allclose(cs.derivative(-1.0), 0.0)
    # inside the set's span the hip (0.1..0.6) holds while the others move
    d = cs.derivative(0.05)
    assert d[1] == 0.0 and d[0] != 0.0 and d[2] == pytest.approx(2.0)
    assert cs.evaluate(0.8)[1] == pytest.approx(0.2)


def test_clamped_ends_have_zero_slope() -> None:
    f = ControlFunction(*HIP, bc_type="clamped")
    assert float(f.derivative(0.1)) == pytest.approx(0.0, abs=1e-12)
    assert float(f.derivative(0.6 - 1e-9)) == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize(
    ("times", "values", "field"),
    [
        ([0.0], [1.0], "at least 2"),
        ([0.0, 1.0], [1.0], "values has 1"),
        ([0.0, 0.5, 0.5], [1.0, 2.0, 3.0], r"strictly increasing \(times\[2\]"),
        ([0.0, 1.0, 0.5], [1.0, 2.0, 3.0], "strictly increasing"),
        ([0.0, np.nan], [1.0, 2.0], "times contains NaN"),
        ([0.0, 1.0], [1.0, np.inf], "values contains NaN or inf at \\[1\\]"),
        ([[0.0, 1.0]], [1.0, 2.0], "times must be a 1-D"),
        (["a", "b"], [1.0, 2.0], "times must be numbers"),
    ],
)
def test_bad_points_raise_config_error_naming_dof_and_field(
    times: list, values: list, field: str
) -> None:
    with pytest.raises(ConfigError, match=f"'l_knee'.*{field}"):
        ControlFunctionSet({"l_knee": (times, values)})


def test_bad_set_arguments() -> None:
    with pytest.raises(ConfigError, match="kind"):
        ControlFunctionSet({"a": ELBOW}, kind="position")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="at least one"):
        ControlFunctionSet({})
    with pytest.raises(ConfigError, match=r"'a'.*bc_type"):
        ControlFunction(*ELBOW, bc_type="periodic", dof="a")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match=r"'b'.*ControlFunction or"):
        ControlFunctionSet({"b": 3.0})  # type: ignore[dict-item]
    with pytest.raises(UnknownKeyError, match="valid keys: \\['knee', 'hip', 'elbow'\\]"):
        _set()["wrist"]
    with pytest.raises(ConfigError, match="shape \\(3,\\)"):
        _set().evaluate(0.0, out=np.empty(2))
    with pytest.raises(ConfigError, match="contiguous"):
        _set().evaluate(0.0, out=np.empty(6)[::2])
    assert _set().kind == "angle" and ControlFunctionSet({"a": ELBOW}, "torque").kind == "torque"
    assert ControlFunctionSet({"a": ControlFunction(*ELBOW)})["a"].dof == "a"


def test_evaluate_into_out_allocates_no_per_step_arrays() -> None:
    rng = np.random.default_rng(0)
    curves = {
        f"dof{i}": (np.cumsum(rng.uniform(0.05, 0.3, 6)), rng.normal(size=6)) for i in range(1000)
    }
    cs = ControlFunctionSet(curves, kind="torque")
    out = np.empty(len(cs))
    ts = [float(t) for t in np.linspace(0.0, 2.0, 200)]
    cs.evaluate(ts[0], out=out)
    cs.derivative(ts[0], out=out)
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    for t in ts:
        cs.evaluate(t, out=out)
        cs.derivative(t, out=out)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak - base < 2000  # one temporary of 1000 float64 would be 8000 bytes


@settings(max_examples=60, deadline=None)
@given(
    steps=st.lists(st.floats(0.01, 5.0), min_size=1, max_size=8),
    t0=st.floats(-10.0, 10.0),
    data=st.data(),
    bc=st.sampled_from(["not-a-knot", "natural", "clamped"]),
)
def test_property_interpolates_control_points(
    steps: list[float], t0: float, data: st.DataObject, bc: str
) -> None:
    times = t0 + np.concatenate([[0.0], np.cumsum(steps)])
    values = data.draw(st.lists(st.floats(-100.0, 100.0), min_size=times.size, max_size=times.size))
    f = ControlFunction(times, values, bc_type=bc)  # type: ignore[arg-type]
    scale = 1e-9 * (1.0 + max(abs(v) for v in values))
    np.testing.assert_allclose(f(times), values, atol=scale)
    cs = ControlFunctionSet({"a": f, "b": (times[::-1] * -1.0, values[::-1])})
    for t, v, w in zip(times, values, values[::-1]):
        np.testing.assert_allclose(cs.evaluate(float(t)), [v, float(cs["b"](t))], atol=scale)
        assert float(cs["b"](-t)) == pytest.approx(v, abs=scale)
        del w

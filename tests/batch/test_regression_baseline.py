"""The golden regression test: the 8-direction sweep of ``examples/sweep_small.toml`` on the real
response pipeline against ``tests/baselines/sweep_small.json`` in strict mode, with tight
per-metric tolerances stored in the baseline. Any drift (a changed default, a changed
algorithm) fails until the baseline is refreshed on purpose:

    reactmocap batch examples/sweep_small.toml --out out/sweep_small
    reactmocap regress out/sweep_small --baseline tests/baselines/sweep_small.json --update

``--update`` keeps the file's tolerances.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from reactmocap.batch import load_sweep, regress, run_batch
from reactmocap.response.scenario import ResponseConfig

from .conftest import EXAMPLES, REPO

BASELINE = REPO / "tests" / "baselines" / "sweep_small.json"
SWEEP = EXAMPLES / "sweep_small.toml"


def _run(out: Path) -> tuple[int, str]:
    res = run_batch(load_sweep(SWEEP), out, runner="serial", progress=False)
    assert res.ran == 8
    return regress(out, BASELINE, strict=True)


def test_small_sweep_matches_the_committed_baseline(warm_cache, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    code, text = _run(tmp_path / "out")
    assert code == 0, (
        f"\n{text}\n(regenerate the baseline if this change is intended: see the module docstring)"
    )


@pytest.mark.parametrize("delay", [0.1, 0.2])
def test_a_changed_reaction_delay_default_fails_it(
    warm_cache, tmp_path: Path, monkeypatch, delay
) -> None:  # type: ignore[no-untyped-def]
    # Change the default itself, as an edit of ResponseConfig would (sweep_small.toml sets no
    # [response], so the default is what runs); the serial runner runs in this process.
    names = list(ResponseConfig.__dataclass_fields__)
    defaults = list(ResponseConfig.__init__.__defaults__)  # type: ignore[misc]
    offset = len(names) - len(defaults)
    defaults[names.index("reaction_delay") - offset] = delay
    monkeypatch.setattr(ResponseConfig.__init__, "__defaults__", tuple(defaults))
    assert ResponseConfig().reaction_delay == delay
    code, text = _run(tmp_path / "out")
    assert code == 1, text
    assert "beyond tolerance" in text

"""Options made of comma-separated numbers (``--push``, ``--force``, ``--com-offset``, a
bicycle's ``--path``, a query's ``--shift``) share one parser: a wrong count, a non-number or a
non-finite value is refused at parse time, naming the expected form."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from reactmocap.cli import main
from reactmocap.commands import numbers

REPO = Path(__file__).resolve().parents[1]
GUARD = str(REPO / "data" / "synthetic_clips" / "guard.bvh")


def test_numbers_parses_exactly_count_finite_values() -> None:
    parse = numbers(2, "X,Y", "m")
    assert parse("1.5,-2") == (1.5, -2.0)
    for bad in ("1", "1,2,3", "1,x", "1,nan", "inf,0", ""):
        with pytest.raises(argparse.ArgumentTypeError, match=r"expected X,Y \(m\), got"):
            parse(bad)


@pytest.mark.parametrize(
    ("argv", "form"),
    [
        (["athletics", "run", "--speed", "3.5", "--push=1,nan"], "TIME,IMPULSE"),
        (["push", GUARD, "--time", "0.1", "--body", "chest", "--force=1,2", "--out", "{tmp}/x.bvh"], "FX,FY,FZ"),
        (["athletics", "balance", "--com-offset", "0.1"], "X,Y"),
        (["athletics", "bicycle", "--speed", "5", "--path", "1,2", "3"], "X,Y"),
        (["search", "query", "idx", "--clip", "a", "--frame", "1", "--shift", "1"], "X,Y"),
    ],
)  # fmt: skip
def test_a_bad_number_option_is_refused_before_running(
    argv: list[str], form: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        main([a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert exc.value.code == 2
    assert f"expected {form} (" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []

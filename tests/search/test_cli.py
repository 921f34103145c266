"""``reactmocap search build|query`` smoke tests through :func:`reactmocap.cli.main`."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reactmocap.cli import main
from reactmocap.library import bvh  # noqa: F401  # a broken BVH module fails here, not skips


@pytest.fixture(scope="module")
def library_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from reactmocap.library.synth import write_synthetic_library

    d = tmp_path_factory.mktemp("lib")
    write_synthetic_library(d, fps=60.0)
    return d


@pytest.fixture(scope="module")
def index_file(library_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("idx") / "synthetic.npz"
    assert main(["search", "build", str(library_dir), "--out", str(out), "--mirror"]) == 0
    return out


def test_build_and_query_json(index_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    argv = ["search", "query", str(index_file), "--clip", "side_kick", "--frame", "20",
            "--yaw", "90", "--shift=-1.5,2", "--top", "3", "--json"]  # fmt: skip
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("clip", "frame", "distance", "yaw_deg", "translation", "query_ms", "candidates"):
        assert key in out
    assert (out["clip"], out["frame"]) == ("side_kick", 20)
    assert out["distance"] < 1e-4
    assert out["yaw_deg"] == pytest.approx(90.0, abs=1e-3)
    assert out["translation"] == pytest.approx([-1.5, 2.0], abs=1e-4)
    assert len(out["candidates"]) == 3
    assert out["candidates"][0]["clip"] == "side_kick"
    assert out["query_ms"] > 0


def test_query_table_and_mirrored_clip(
    index_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    capsys.readouterr()
    assert (
        main(["search", "query", str(index_file), "--clip", "punch_mirror", "--frame", "10"]) == 0
    )
    text = capsys.readouterr().out
    assert "punch_mirror" in text and "trunk_p" in text


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--clip", "no_such_clip", "--frame", "0"], "no clip named 'no_such_clip'"),
        (["--clip", "punch", "--frame", "100000"], "out of range"),
        (["--clip", "punch", "--frame", "-5"], "out of range"),
    ],
)
def test_query_errors(
    index_file: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    capsys.readouterr()
    assert main(["search", "query", str(index_file), *extra]) == 2
    assert message in capsys.readouterr().err


def test_bad_index_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.npz"
    bad.write_text("garbage")
    assert main(["search", "query", str(bad), "--clip", "x", "--frame", "0"]) == 2
    err = capsys.readouterr().err
    assert "bad.npz" in err and "search index" in err


def test_bad_shift_is_a_usage_error(tmp_path: Path) -> None:
    with pytest.raises(SystemExit):
        main(
            [
                "search",
                "query",
                str(tmp_path / "x.npz"),
                "--clip",
                "a",
                "--frame",
                "0",
                "--shift",
                "1",
            ]
        )


@pytest.mark.parametrize("yaw", ["nan", "inf", "abc"])
def test_a_yaw_that_is_no_angle_is_a_usage_error_naming_it(
    yaw: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["search", "query", str(tmp_path / "x.npz"), "--clip", "a", "--frame", "0"]
    with pytest.raises(SystemExit) as exc:
        main([*args, "--yaw", yaw])
    assert exc.value.code == 2
    assert (
        f"argument --yaw: expected a finite angle in degrees, got '{yaw}'"
        in capsys.readouterr().err
    )

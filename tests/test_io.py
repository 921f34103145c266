"""Output paths that cannot be written: a typed error naming the path, before any computation
on the command line, and never a half-written file."""

from __future__ import annotations

from pathlib import Path

import pytest

from reactmocap.cli import main
from reactmocap.errors import OutputError, ReactMocapError
from reactmocap.io import atomic_write_text, staged_files, unwritable_reason
from reactmocap.library.bvh import read_bvh, write_bvh

REPO = Path(__file__).resolve().parents[1]
GUARD = REPO / "data" / "synthetic_clips" / "guard.bvh"


def test_writing_under_a_file_is_a_typed_error_naming_it(tmp_path: Path) -> None:
    # before: FileExistsError / NotADirectoryError with a traceback from mkdir
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    with pytest.raises(OutputError, match=f"cannot write {blocker}/sub/x.bvh: {blocker} is a file"):
        write_bvh(read_bvh(GUARD), blocker / "sub" / "x.bvh")
    with pytest.raises(ReactMocapError):
        atomic_write_text(blocker / "r.json", "{}")
    with pytest.raises(OSError):  # callers that tolerate an OSError (the clip cache) still do
        atomic_write_text(blocker / "r.json", "{}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


def test_staged_files_are_all_or_none(tmp_path: Path) -> None:
    a, b = tmp_path / "a.txt", tmp_path / "sub" / "b.json"
    with pytest.raises(RuntimeError), staged_files() as stage:
        stage(a).write_text("A")
        stage(b).write_text("B")
        raise RuntimeError("the third output failed")
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == []
    with staged_files() as stage:
        stage(a).write_text("A")
        stage(b).write_text("B")
        assert not a.exists()  # nothing in place before the block succeeds
    assert (a.read_text(), b.read_text()) == ("A", "B")
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == ["a.txt", "b.json"]


def test_unwritable_reason(tmp_path: Path) -> None:
    assert unwritable_reason(tmp_path / "new" / "deeper" / "x.bvh") is None  # folders made
    (tmp_path / "afile").write_text("x")
    assert (
        unwritable_reason(tmp_path / "afile" / "x.bvh")
        == f"{tmp_path / 'afile'} is a file, not a folder"
    )


@pytest.mark.parametrize(
    "argv",
    [
        ["track", str(GUARD), "--seconds", "0.3", "--out", "{bad}/x.bvh"],
        ["track", str(GUARD), "--seconds", "0.3", "--out", "{dir}/x.bvh", "--report", "{bad}/r.json"],
        ["convert", str(GUARD), "{bad}/x.bvh"],
        ["synth", "{bad}/clips"],
        ["respond", str(REPO / "examples" / "light_push.toml"), "--out", "{bad}"],
        ["demo", "--out", "{bad}/demo"],
        ["athletics", "maneuver", str(REPO / "examples/athletics/maneuvers/vertical_leap.toml"),
         "--out", "{bad}/m"],
        ["athletics", "bicycle", "--speed", "5", "--out", "{bad}/ride"],
    ],
    ids=lambda a: "-".join(a[:2]) if a[0] == "athletics" else a[0] + ("-report" if "--report" in a else ""),
)  # fmt: skip
def test_an_unwritable_output_is_refused_before_running(
    argv: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # before: the command ran to the end, then failed with an OSError traceback (track with
    # --report there had already written its BVH)
    bad = tmp_path / "afile"
    bad.write_text("x")
    args = [a.replace("{bad}", str(bad)).replace("{dir}", str(tmp_path)) for a in argv]
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and str(bad) in err.splitlines()[-1]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]

"""Clip library: recursive loading, the content-hash cache, lenient/strict modes, stats, CLI."""

from __future__ import annotations

import shutil
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from reactmocap.cli import main
from reactmocap.errors import BVHParseError, LibraryError
from reactmocap.library.clip_library import load_library
from tests.conftest import SYNTHETIC


@pytest.fixture()
def small_lib(tmp_path: Path) -> Path:
    lib = tmp_path / "lib"
    (lib / "sub").mkdir(parents=True)
    clips = sorted(SYNTHETIC.glob("*.bvh"))[:3]
    assert clips, "synthetic clips missing"
    shutil.copy(clips[0], lib / clips[0].name)
    shutil.copy(clips[1], lib / clips[1].name)
    shutil.copy(clips[2], lib / "sub" / clips[2].name)
    return lib


def test_recursive_load_names_and_stats(small_lib: Path, tmp_path: Path) -> None:
    lib = load_library(small_lib, cache_dir=tmp_path / "c")
    assert len(lib) == 3
    assert any(name.startswith("sub/") for name in lib)
    st = lib.stats()
    assert st.clips == 3
    assert st.frames == sum(m.num_frames for m in lib.clips.values())
    assert st.skeletons == 1
    assert st.fps == (60.0,)
    with pytest.raises(LibraryError, match="no clip named 'nope'"):
        lib["nope"]


def test_cache_hit_equal_and_invalidated_on_change(small_lib: Path, tmp_path: Path) -> None:
    cache = tmp_path / "c"
    first = load_library(small_lib, cache_dir=cache)
    entries = sorted(cache.glob("*.npz"))
    assert len(entries) == 3
    second = load_library(small_lib, cache_dir=cache)
    for name, m in first.clips.items():
        np.testing.assert_array_equal(second[name].rotations, m.rotations)
        np.testing.assert_array_equal(second[name].root_positions, m.root_positions)
        assert second[name].skeleton == m.skeleton
        assert second[name].skeleton.layout == m.skeleton.layout
    assert first.fingerprint() == second.fingerprint()
    # editing a file changes its hash: new cache entry, new fingerprint, new content
    target = sorted(small_lib.glob("*.bvh"))[0]
    lines = target.read_text().splitlines()
    last = lines[-1].split()
    last[0] = f"{float(last[0]) + 10.0:.6f}"
    lines[-1] = " ".join(last)
    target.write_text("\n".join(lines) + "\n")
    third = load_library(small_lib, cache_dir=cache)
    assert third.fingerprint() != first.fingerprint()
    assert len(sorted(cache.glob("*.npz"))) == 4
    name = target.stem
    assert not np.allclose(third[name].root_positions[-1], first[name].root_positions[-1])


def test_cache_reads_never_overlap_in_the_thread_pool(
    small_lib: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """numpy parses .npy headers with ast.literal_eval, which CPython 3.11 does not make
    thread-safe (a CI run raised "AST constructor recursion depth mismatch" on a cache read):
    the pool's cache reads go one at a time, while their files are read by three workers."""
    cache = tmp_path / "c"
    first = load_library(small_lib, cache_dir=cache)
    real_load = np.load
    active, most = [0], [0]
    guard = threading.Lock()

    def slow_load(*args: object, **kwargs: object) -> object:
        with guard:
            active[0] += 1
            most[0] = max(most[0], active[0])
        time.sleep(0.05)  # a read long enough for the other workers to reach theirs
        try:
            return real_load(*args, **kwargs)  # type: ignore[arg-type]
        finally:
            with guard:
                active[0] -= 1

    monkeypatch.setattr(np, "load", slow_load)
    again = load_library(small_lib, cache_dir=cache, workers=3)
    assert most[0] == 1
    assert sorted(again.clips) == sorted(first.clips)
    for name, m in first.clips.items():
        assert np.array_equal(again.clips[name].rotations, m.rotations)


def test_corrupt_cache_entry_is_reparsed(small_lib: Path, tmp_path: Path) -> None:
    cache = tmp_path / "c"
    first = load_library(small_lib, cache_dir=cache)
    for entry in cache.glob("*.npz"):
        entry.write_bytes(b"garbage")
    again = load_library(small_lib, cache_dir=cache)
    for name, m in first.clips.items():
        np.testing.assert_array_equal(again[name].rotations, m.rotations)


def test_lenient_lists_bad_files_and_strict_raises(small_lib: Path, tmp_path: Path) -> None:
    (small_lib / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    lib = load_library(small_lib, cache_dir=tmp_path / "c")
    assert len(lib) == 3
    assert [f.path.name for f in lib.failures] == ["broken.bvh"]
    assert "broken.bvh" in lib.failures[0].reason
    with pytest.raises(BVHParseError, match="broken.bvh"):
        load_library(small_lib, cache_dir=tmp_path / "c", strict=True)
    with pytest.raises(LibraryError, match="no .bvh files"):
        load_library(tmp_path / "c", cache=False)


def test_mirror_doubles_library(small_lib: Path, tmp_path: Path) -> None:
    lib = load_library(small_lib, cache_dir=tmp_path / "c", mirror=True)
    assert len(lib) == 6
    assert sum(name.endswith("_mirror") for name in lib) == 3


def test_cli_info_check_convert(
    small_lib: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["library", "info", str(small_lib)]) == 0
    out = capsys.readouterr().out
    assert "total" in out and "3 clips" in out
    assert main(["library", "check", str(small_lib)]) == 0
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\n")
    assert main(["library", "check", str(small_lib), str(bad)]) == 1
    out = capsys.readouterr().out
    assert "bad.bvh" in out and "1 bad" in out
    src = sorted(small_lib.glob("*.bvh"))[0]
    dst = tmp_path / "out.bvh"
    assert main(["convert", str(src), str(dst), "--fps", "30", "--mirror"]) == 0
    from reactmocap.library.bvh import read_bvh

    conv = read_bvh(dst)
    assert conv.fps == pytest.approx(30.0)
    assert main(["convert", str(tmp_path / "missing.bvh"), str(dst)]) == 2
    assert "missing.bvh" in capsys.readouterr().err


def test_cli_check_counts_a_missing_path_as_bad_not_as_a_negative_ok(
    small_lib: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a missing path or a folder without BVH files is one bad entry; no file was read, so
    # nothing is ok (it printed "-1 ok, 1 bad" before)
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["library", "check", str(tmp_path / "missing.bvh"), str(empty)]) == 1
    assert capsys.readouterr().out.splitlines()[-1].startswith("0 ok, 2 bad")
    assert main(["library", "check", str(small_lib), str(tmp_path / "missing.bvh")]) == 1
    assert capsys.readouterr().out.splitlines()[-1].startswith("3 ok, 1 bad")


def test_cli_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert "reactmocap 0.1.0" in capsys.readouterr().out

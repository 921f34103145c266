"""A folder of BVH clips loaded into Motions, with an ``.npz`` cache keyed by file content.

The cache stores the parsed arrays (no pickle) under ``REACTMOCAP_CACHE_DIR`` or
``~/.cache/reactmocap/clips``; an entry's name is the SHA-256 of the file bytes plus the loader
options and format version, so editing a file invalidates its entry automatically.
"""

from __future__ import annotations

import hashlib
import os
import threading
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reactmocap.conventions import UpAxis
from reactmocap.errors import LibraryError, ReactMocapError
from reactmocap.io import atomic_write_bytes, npz_bytes, npz_meta
from reactmocap.library.bvh import read_bvh
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import BVHLayout, Skeleton

__all__ = [
    "ClipLibrary",
    "ClipLoadFailure",
    "LibraryStats",
    "default_cache_dir",
    "find_bvh_files",
    "load_clip",
    "load_library",
]

_CACHE_VERSION = "1"


def default_cache_dir() -> Path:
    env = os.environ.get("REACTMOCAP_CACHE_DIR")
    return Path(env) if env else Path.home() / ".cache" / "reactmocap" / "clips"


def find_bvh_files(path: str | Path) -> list[Path]:
    """BVH files under ``path`` (recursively, sorted), or ``[path]`` for a file."""
    p = Path(path)
    if p.is_file():
        return [p]
    if not p.is_dir():
        raise LibraryError(f"{p}: no such file or folder")
    return sorted(f for f in p.rglob("*") if f.is_file() and f.suffix.lower() == ".bvh")


@dataclass(frozen=True)
class ClipLoadFailure:
    path: Path
    reason: str


@dataclass(frozen=True)
class LibraryStats:
    clips: int
    frames: int
    seconds: float
    fps: tuple[float, ...]
    skeletons: int


@dataclass
class ClipLibrary:
    """Clips by name (path relative to the root, without ``.bvh``, ``/``-separated)."""

    root: Path
    clips: dict[str, Motion]
    paths: dict[str, Path] = field(default_factory=dict)
    hashes: dict[str, str] = field(default_factory=dict)
    failures: list[ClipLoadFailure] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.clips)

    def __iter__(self) -> Iterator[str]:
        return iter(self.clips)

    def __contains__(self, name: object) -> bool:
        return name in self.clips

    def __getitem__(self, name: str) -> Motion:
        key = name[:-4] if name.lower().endswith(".bvh") else name
        if key in self.clips:
            return self.clips[key]
        raise LibraryError(
            f"no clip named {name!r} in library {self.root}; clips are {sorted(self.clips)}"
        )

    def stats(self) -> LibraryStats:
        motions = list(self.clips.values())
        structures = {(m.skeleton.names, m.skeleton.parents.tobytes()) for m in motions}
        return LibraryStats(
            clips=len(motions),
            frames=sum(m.num_frames for m in motions),
            seconds=float(sum(m.num_frames / m.fps for m in motions)),
            fps=tuple(sorted({round(m.fps, 4) for m in motions})),
            skeletons=len(structures),
        )

    def fingerprint(self) -> str:
        """Content hash of every clip file (names and bytes), for invalidating derived data."""
        h = hashlib.sha256()
        for name in sorted(self.hashes):
            h.update(f"{name}\0{self.hashes[name]}\n".encode())
        return h.hexdigest()

    def with_mirrors(self, suffix: str = "_mirror") -> ClipLibrary:
        """This library plus a left/right mirrored copy of every clip (doubles coverage)."""
        clips = dict(self.clips)
        hashes = dict(self.hashes)
        for name, m in self.clips.items():
            clips[name + suffix] = m.mirror().replace(name=name + suffix)
            hashes[name + suffix] = self.hashes.get(name, "") + "+mirror"
        return ClipLibrary(self.root, clips, dict(self.paths), hashes, list(self.failures))


def _file_hash(data: bytes, unit: str | None, up: str) -> str:
    h = hashlib.sha256(data)
    h.update(f"|v{_CACHE_VERSION}|{unit}|{up}".encode())
    return h.hexdigest()


def _to_npz(m: Motion) -> bytes:
    s = m.skeleton
    meta = {
        "name": m.name,
        "fps": m.fps,
        "names": list(s.names),
        "channels": [list(c) for c in s.layout.channels],
        "unit": s.layout.unit,
        "up": s.layout.up,
        "end_sites": {str(k): list(v) for k, v in s.layout.end_sites.items()},
    }
    arrays = {
        "parents": s.parents,
        "offsets": s.offsets,
        "root_positions": m.root_positions,
        "rotations": m.rotations,
    }
    if m.translations is not None:
        arrays["translations"] = m.translations
    return npz_bytes(meta, arrays)


# numpy reads each .npy header with ast.literal_eval, and CPython 3.11's AST construction is
# not thread-safe: the library's thread pool raised "SystemError: AST constructor recursion
# depth mismatch" on a cache read (CI, 2026-12-04; python/cpython#106905). Cache reads take
# milliseconds, so they go one at a time; the BVH parsing stays parallel.
_NPZ_READ = threading.Lock()


def _from_npz(path: Path) -> Motion:
    with _NPZ_READ, np.load(path, allow_pickle=False) as z:
        meta = npz_meta(z)
        layout = BVHLayout(
            channels=tuple(tuple(c) for c in meta["channels"]),
            unit=meta["unit"],
            up=meta["up"],
            end_sites={int(k): tuple(v) for k, v in meta["end_sites"].items()},
        )
        skel = Skeleton(tuple(meta["names"]), z["parents"], z["offsets"], layout)
        tr = z["translations"] if "translations" in z.files else None
        return Motion(skel, meta["fps"], z["root_positions"], z["rotations"], tr, meta["name"])


def load_clip(
    path: str | Path,
    *,
    name: str | None = None,
    cache_dir: Path | None = None,
    unit: str | None = None,
    up: UpAxis = "y",
) -> tuple[Motion, str]:
    """Load one BVH through the cache. Returns the Motion and the file's content hash."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise LibraryError(f"{p}: cannot read: {exc.strerror}") from None
    key = _file_hash(data, unit, up)
    entry = cache_dir / f"{key}.npz" if cache_dir is not None else None
    if entry is not None and entry.exists():
        try:
            return _from_npz(entry).replace(name=name or p.stem), key
        except (ReactMocapError, OSError, ValueError, KeyError):
            pass  # corrupt or stale entry: fall through and re-parse
    motion = read_bvh(p, unit=unit, up=up, name=name or p.stem)  # type: ignore[arg-type]
    if entry is not None:
        try:
            atomic_write_bytes(entry, _to_npz(motion))
        except OSError:
            pass  # a read-only cache must not stop loading
    return motion, key


def load_library(
    path: str | Path,
    *,
    strict: bool = False,
    cache: bool = True,
    cache_dir: str | Path | None = None,
    workers: int | None = None,
    unit: str | None = None,
    up: UpAxis = "y",
    mirror: bool = False,
) -> ClipLibrary:
    """Load every BVH file under ``path``.

    Lenient (default): bad files are skipped and listed in ``failures`` with the reason.
    Strict: the first bad file raises. Files are parsed in a thread pool (parsing is numpy-bound).
    """
    root = Path(path)
    files = find_bvh_files(root)
    if not files:
        raise LibraryError(f"{root}: no .bvh files found")
    cdir = (Path(cache_dir) if cache_dir else default_cache_dir()) if cache else None
    base = root if root.is_dir() else root.parent

    def name_of(f: Path) -> str:
        return f.relative_to(base).with_suffix("").as_posix()

    def job(f: Path) -> tuple[Motion, str] | ClipLoadFailure:
        try:
            return load_clip(f, name=name_of(f), cache_dir=cdir, unit=unit, up=up)
        except ReactMocapError as exc:
            if strict:
                raise
            return ClipLoadFailure(f, str(exc))

    n = workers or min(8, (os.cpu_count() or 2) * 2, len(files))
    with ThreadPoolExecutor(max_workers=max(1, n)) as pool:
        results = list(pool.map(job, files))
    lib = ClipLibrary(root, {})
    for f, r in zip(files, results):
        if isinstance(r, ClipLoadFailure):
            lib.failures.append(r)
            continue
        motion, key = r
        nm = name_of(f)
        lib.clips[nm] = motion
        lib.paths[nm] = f
        lib.hashes[nm] = key
    if not lib.clips:
        reasons = "; ".join(f"{x.path.name}: {x.reason}" for x in lib.failures[:5])
        raise LibraryError(f"{root}: no clip could be loaded ({reasons})")
    return lib.with_mirrors() if mirror else lib

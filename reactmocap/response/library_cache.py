"""Clip libraries and their search indexes for the response pipeline, loaded once and kept in a
:class:`LibraryCache` that its caller owns (a batch job holds one per worker). Clips on other
skeletons than the recipient's are retargeted onto it, so any clip can be the continuation."""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path
from typing import Generic, TypeVar

import numpy as np

from reactmocap import __version__
from reactmocap.errors import LibraryError, ReactMocapError
from reactmocap.library.bodyparts import parts_for
from reactmocap.library.clip_library import (
    ClipLibrary,
    ClipLoadFailure,
    default_cache_dir,
    find_bvh_files,
    load_library,
)
from reactmocap.library.motion import Motion
from reactmocap.search import MotionIndex, SearchWeights, WindowConfig
from reactmocap.search.index import FORMAT_VERSION as INDEX_FORMAT_VERSION
from reactmocap.sim.character import build_character
from reactmocap.sim.retarget import Retargeter

__all__ = ["RETARGET_VERSION", "LibraryCache", "prepare_library"]

#: bump when retargeting changes, so indexes of retargeted clips are rebuilt
RETARGET_VERSION = 1
K = TypeVar("K")
V = TypeVar("V")


class _Lru(Generic[K, V]):
    def __init__(self, size: int) -> None:
        self.size = size
        self.items: OrderedDict[K, V] = OrderedDict()

    def get(self, key: K) -> V | None:
        if key in self.items:
            self.items.move_to_end(key)
            return self.items[key]
        return None

    def put(self, key: K, value: V) -> V:
        self.items[key] = value
        self.items.move_to_end(key)
        while len(self.items) > self.size:
            self.items.popitem(last=False)
        return value


class LibraryCache:
    """The last ``size`` clip libraries (keyed by their files' names, sizes and mtimes: a batch
    runs many responses over one library, and re-hashing every file costs ~45 ms) and search
    indexes (keyed by content and recipient skeleton; also cached on disk) a caller used."""

    def __init__(self, size: int = 4) -> None:
        self._libraries: _Lru[tuple[object, ...], ClipLibrary] = _Lru(size)
        self._indexes: _Lru[tuple[str, ...], tuple[ClipLibrary, MotionIndex]] = _Lru(size)

    def library(self, path: Path) -> ClipLibrary:
        files = find_bvh_files(path)
        key = (str(Path(path).resolve()),
               tuple((str(f), (st := f.stat()).st_size, st.st_mtime_ns) for f in files))  # fmt: skip
        return self._libraries.get(key) or self._libraries.put(key, load_library(path))

    def search(
        self, path: Path, recipient: Motion, rules: Path | None = None
    ) -> tuple[ClipLibrary, MotionIndex]:
        """The library as continuations for ``recipient`` (retargeted onto its skeleton) and
        their index; clips no rule maps are skipped (listed in the library's ``failures``)."""
        return prepare_library(path, recipient, self.library(path), self, rules)

    def _index(
        self,
        key: tuple[str, ...],
        lib: ClipLibrary,
        make_clips: Callable[[], dict[str, Motion]],
        rules: Path | None,
        skipped: list[ClipLoadFailure],
    ) -> tuple[ClipLibrary, MotionIndex]:
        hit = self._indexes.get(key)
        if hit is not None:
            return hit
        clips = make_clips()  # retargeting only on a miss: the key already says what it gives
        parts = {n: parts_for(m.skeleton, rules) for n, m in clips.items()}
        digest = hashlib.sha256("\0".join(key).encode()).hexdigest()[:16]  # stable across runs
        index_path = default_cache_dir().parent / "indexes" / f"{digest}.npz"
        index = MotionIndex.load_or_build(index_path, clips, SearchWeights(), WindowConfig(),
                                          parts=parts)  # fmt: skip
        sub = ClipLibrary(lib.root, clips, lib.paths, lib.hashes, [*lib.failures, *skipped])
        return self._indexes.put(key, (sub, index))


def prepare_library(
    path: Path,
    skeleton_of: Motion | None = None,
    lib: ClipLibrary | None = None,
    cache: LibraryCache | None = None,
    rules: Path | None = None,
) -> tuple[ClipLibrary, MotionIndex]:
    """A clip library (loaded unless given) and its search index (cached on disk, keyed by
    content, by ``skeleton_of``'s skeleton and the body-part ``rules``). Clips whose skeleton no
    rule maps are skipped and listed in the returned library's ``failures``. With
    ``skeleton_of``, clips on other skeletons are retargeted onto it (the source side's reference
    pose is frame 0 of its alphabetically first clip, the target's frame 0 of ``skeleton_of``,
    so the key then holds ``skeleton_of``'s content too)."""
    lib = load_library(path) if lib is None else lib
    clips: dict[str, Motion] = {}
    skipped: list[ClipLoadFailure] = []
    for name, m in lib.clips.items():
        try:
            parts_for(m.skeleton, rules)
        except ReactMocapError as exc:
            skipped.append(ClipLoadFailure(lib.paths.get(name, Path(name)), str(exc)))
            continue
        clips[name] = m
    if not clips:
        raise LibraryError(f"{path}: no clip of the library can be mapped onto body parts "
                           f"({skipped[0].reason})")  # fmt: skip
    target = ""
    if skeleton_of is not None:
        sk = skeleton_of.skeleton
        target = hashlib.sha256(
            ("\0".join(sk.names) + repr(np.round(sk.offsets, 6).tolist())).encode()
        ).hexdigest()[:12]
        if any(not m.skeleton.same_structure(sk) for m in clips.values()):
            # retargeted clips depend on the recipient's clip (its frame 0 sets the anatomical
            # frames, its lowest feet the soles), not only on its skeleton: keyed on the
            # skeleton alone, the cache gave every recipient the clips retargeted for the first
            # one in the process, so a response depended on what ran before it
            target += "/" + _motion_digest(skeleton_of)
    rules_key = hashlib.sha256(Path(rules).read_bytes()).hexdigest()[:12] if rules else ""
    # the code versions are part of the key: an index written by older search code is not reused
    key = (str(Path(path).resolve()), ",".join(sorted(clips)) + lib.fingerprint(),
           f"{__version__}/{INDEX_FORMAT_VERSION}/retarget{RETARGET_VERSION}/{target}/{rules_key}")  # fmt: skip

    def make() -> dict[str, Motion]:
        return clips if skeleton_of is None else _retargeted(clips, skeleton_of, rules)

    return (cache or LibraryCache(1))._index(key, lib, make, rules, skipped)


def _motion_digest(motion: Motion) -> str:
    """Content hash of a motion's arrays (what a retargeting onto it reads)."""
    h = hashlib.sha256(np.float64(motion.fps).tobytes())
    for a in (motion.root_positions, motion.rotations, motion.translations):
        if a is not None:
            h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    return h.hexdigest()[:12]


def _retargeted(
    clips: dict[str, Motion], recipient: Motion, rules: Path | None = None
) -> dict[str, Motion]:
    """Every clip on ``recipient``'s skeleton: same-structure clips as they are, the rest
    retargeted (one Retargeter per source skeleton)."""
    target_char = None
    by_skeleton: list[Retargeter] = []
    out: dict[str, Motion] = {}
    for name in sorted(clips):
        m = clips[name]
        if m.skeleton.same_structure(recipient.skeleton):
            out[name] = m
            continue
        if target_char is None:
            target_char = build_character(recipient, parts_for(recipient.skeleton, rules), frame=0)
        r = next((r for r in by_skeleton if r.source.skeleton.same_structure(m.skeleton)), None)
        if r is None:
            r = Retargeter(build_character(m, parts_for(m.skeleton, rules), frame=0), target_char)
            by_skeleton.append(r)
        out[name] = r(m)
    return out

"""Saving and loading a :class:`~reactmocap.search.index.MotionIndex`: an atomic ``.npz`` of its
arrays plus JSON metadata (no pickle), validated on load, and rejected as stale when the library
or the settings it was built from have changed."""

from __future__ import annotations

import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from reactmocap.errors import ReactMocapError, SearchError
from reactmocap.io import atomic_write_bytes, npz_bytes, npz_meta
from reactmocap.library.motion import Motion
from reactmocap.search.build import build_index, clip_source
from reactmocap.search.config import SearchWeights, WindowConfig
from reactmocap.search.index import ARRAYS, MotionIndex
from reactmocap.search.types import FORMAT_VERSION

__all__ = ["load", "load_or_build", "save", "stale_reason"]

_FORMAT = "reactmocap-search-index"


def save(index: MotionIndex, path: str | Path) -> Path:
    """Write ``index`` atomically as ``.npz`` (arrays + JSON metadata, no pickle)."""
    p = Path(path)
    meta = {
        "format": _FORMAT,
        "version": FORMAT_VERSION,
        "weights": index.weights.to_dict(),
        "window": index.window.to_dict(),
        "mirror": index.mirror,
        "clip_names": list(index.clip_names),
        "library_hash": index.library_hash,
        "settings_hash": index.settings_hash,
        "info": index.info,
    }
    arrays = {name: getattr(index, name) for name in ARRAYS}
    try:
        atomic_write_bytes(p, npz_bytes(meta, arrays))
    except OSError as exc:
        raise SearchError(f"{p}: cannot write index: {exc}") from None
    return p


def _check_version(p: Path, meta: Any) -> None:
    if not isinstance(meta, dict) or meta.get("format") != _FORMAT:
        raise SearchError(f"{p}: not a reactmocap search index")
    if meta.get("version") != FORMAT_VERSION:
        raise SearchError(
            f"{p}: search index format version {meta.get('version')} is not "
            f"{FORMAT_VERSION}; rebuild it"
        )


def load(
    path: str | Path,
    *,
    clips: Mapping[str, Motion] | Any | None = None,
    weights: SearchWeights | None = None,
    window: WindowConfig | None = None,
    mirror: bool | None = None,
) -> MotionIndex:
    """Read an index written by :func:`save`.

    When ``clips``/``weights``/``window``/``mirror`` are given, the index must have been built
    from exactly those (content fingerprint); otherwise it is stale.

    Raises:
        SearchError: naming the file, when it is missing, not an index, corrupt, of another
            format version, or stale.
    """
    p = Path(path)
    try:
        with np.load(p, allow_pickle=False) as z:
            if "meta" not in z.files:
                raise SearchError(f"{p}: not a reactmocap search index (no metadata)")
            meta = npz_meta(z)
            _check_version(p, meta)  # an older format lacks arrays: say which version it is
            missing = [a for a in ARRAYS if a not in z.files]
            if missing:
                raise SearchError(f"{p}: corrupt search index, missing arrays {missing}")
            arrays = {a: z[a] for a in ARRAYS}
    except SearchError:
        raise
    except FileNotFoundError:
        raise SearchError(f"{p}: no such index file") from None
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, EOFError, UnicodeDecodeError) as exc:
        raise SearchError(
            f"{p}: not a readable search index ({type(exc).__name__}: {exc})"
        ) from None
    try:
        w = SearchWeights.from_dict(meta["weights"])
        win = WindowConfig.from_dict(meta["window"])
        names = tuple(str(n) for n in meta["clip_names"])
        mirrored = bool(meta["mirror"])
        hashes = str(meta["library_hash"]), str(meta["settings_hash"])
        info = dict(meta.get("info", {}))
    except (KeyError, TypeError, ValueError, ReactMocapError) as exc:
        raise SearchError(f"{p}: corrupt search index metadata ({exc})") from None
    try:
        index = MotionIndex(
            weights=w,
            window=win,
            mirror=mirrored,
            clip_names=names,
            library_hash=hashes[0],
            settings_hash=hashes[1],
            info=info,
            **arrays,
        )
    except SearchError as exc:  # inconsistent arrays
        raise SearchError(f"{p}: {exc}") from None
    except (TypeError, ValueError) as exc:  # arrays of the wrong kind
        raise SearchError(f"{p}: corrupt search index ({exc})") from None
    problem = stale_reason(index, clips=clips, weights=weights, window=window, mirror=mirror)
    if problem:
        raise SearchError(f"{p}: stale search index: {problem}; rebuild it")
    return index


def stale_reason(
    index: MotionIndex,
    *,
    clips: Mapping[str, Motion] | Any | None = None,
    weights: SearchWeights | None = None,
    window: WindowConfig | None = None,
    mirror: bool | None = None,
) -> str | None:
    """Why ``index`` does not match the given library/settings, or ``None``."""
    if clips is not None and clip_source(clips)[1] != index.library_hash:
        return "the library's clips changed since it was built"
    if weights is not None and weights != index.weights:
        return f"weights differ (index built with {index.weights})"
    if window is not None and window != index.window:
        return f"window settings differ (index built with {index.window})"
    if mirror is not None and bool(mirror) != index.mirror:
        return f"mirroring differs (index built with mirror={index.mirror})"
    return None


def load_or_build(
    path: str | Path,
    clips: Mapping[str, Motion] | Any,
    weights: SearchWeights | None = None,
    window: WindowConfig | None = None,
    mirror: bool = False,
    **build_kwargs: Any,
) -> MotionIndex:
    """Load ``path`` if it was built from exactly these clips and settings; otherwise (missing,
    corrupt or stale) build the index, save it atomically and return it."""
    weights = weights if weights is not None else SearchWeights()
    window = window if window is not None else WindowConfig()
    p = Path(path)
    if p.exists():
        try:
            return load(p, clips=clips, weights=weights, window=window, mirror=mirror)
        except SearchError:
            pass
    index = build_index(clips, weights, window, mirror, **build_kwargs)
    save(index, p)
    return index

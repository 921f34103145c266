"""Atomic file writing: outputs are written to a temporary sibling and renamed into place, so a
crash or an exception never leaves a half-written file (a set of files: :func:`staged_files`,
all or none); a path that cannot be written raises :class:`~reactmocap.errors.OutputError`
naming it and why. Reading TOML input files with errors that name the file."""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
import tomllib
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from reactmocap.errors import ConfigError, OutputError

__all__ = [
    "atomic_write",
    "atomic_write_bytes",
    "atomic_write_text",
    "npz_bytes",
    "npz_meta",
    "output_errors",
    "read_toml",
    "save_png",
    "StagedFiles",
    "staged_files",
    "unwritable_reason",
]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_write(path: str | Path, mode: str = "w") -> Iterator[IO]:  # type: ignore[type-arg]
    """Open a temporary file beside ``path``; on success rename it over ``path``."""
    target = Path(path)
    with output_errors(target):
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, mode) as fh:
            yield fh
            with output_errors(target):
                fh.flush()
                os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; honour the umask like open()
        with output_errors(target):
            os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


class StagedFiles:
    """The temporary siblings of a set of outputs (see :func:`staged_files`)."""

    def __init__(self) -> None:
        self.files: dict[Path, Path] = {}

    def __call__(self, target: str | Path) -> Path:
        """A new empty temporary file beside ``target`` to write ``target``'s content into."""
        target = Path(target)
        with output_errors(target):
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(
                prefix=f".{target.name}.", suffix=target.suffix, dir=target.parent
            )
        os.close(fd)
        self.files[target] = Path(tmp)
        return Path(tmp)

    def rename(self, old: Path, new: Path) -> None:
        """Move ``old``'s staged file to target ``new`` (a writer that chose another suffix)."""
        self.files[new] = self.files.pop(old)


@contextlib.contextmanager
def staged_files() -> Iterator[StagedFiles]:
    """Stage a set of outputs: ``stage(target)`` gives a temporary sibling to write; when the
    block succeeds every one is renamed over its target, and on any error all are removed, so
    a failure leaves none of the set behind."""
    stage = StagedFiles()
    try:
        yield stage
        mode = 0o666 & ~_umask()  # mkstemp makes 0600; honour the umask like open()
        for target, tmp in stage.files.items():
            with output_errors(target):
                os.chmod(tmp, mode)
                os.replace(tmp, target)
    except BaseException:
        for tmp in stage.files.values():
            with contextlib.suppress(FileNotFoundError):
                tmp.unlink()
        raise


@contextlib.contextmanager
def output_errors(path: str | Path) -> Iterator[None]:
    """Turn an ``OSError`` raised inside into an :class:`OutputError` naming ``path`` and why
    (what :func:`unwritable_reason` finds, else the system's message)."""
    try:
        yield
    except OSError as exc:
        why = unwritable_reason(path) or exc.strerror or str(exc)
        raise OutputError(f"cannot write {path}: {why}") from None


def unwritable_reason(path: str | Path) -> str | None:
    """Why no file can be written at ``path`` (its missing folders are created on writing),
    or None: checked before a long computation, so that it is not lost at the end."""
    folder = Path(path).absolute().parent
    while not folder.exists():
        folder = folder.parent
    if not folder.is_dir():
        return f"{folder} is a file, not a folder"
    if not os.access(folder, os.W_OK | os.X_OK):
        return f"cannot write into {folder} (read-only or no permission)"
    return None


def atomic_write_text(path: str | Path, text: str) -> None:
    with atomic_write(path, "w") as fh:
        fh.write(text)


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    with atomic_write(path, "wb") as fh:
        fh.write(data)


def npz_bytes(meta: Mapping[str, Any], arrays: Mapping[str, NDArray[Any]]) -> bytes:
    """An ``.npz`` of ``arrays`` and ``meta`` as JSON text in a ``meta`` array: a file of
    arrays with its own description and no pickle (the clip cache, the search index)."""
    buf = io.BytesIO()
    text = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    np.savez(buf, meta=text, **arrays)  # type: ignore[arg-type]  # the stub mixes in its bool options
    return buf.getvalue()


def npz_meta(npz: Any) -> Any:
    """The ``meta`` of an ``.npz`` opened with ``np.load`` that :func:`npz_bytes` wrote."""
    return json.loads(bytes(npz["meta"]).decode())


def read_toml(path: str | Path, what: str) -> dict[str, Any]:
    """The table of TOML file ``path`` (a ``what`` file: "scenario", "course", ...); a missing
    or unreadable file or invalid TOML raises :class:`~reactmocap.errors.ConfigError` naming
    the file (and TOML's line and column)."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"{what} file {str(p)!r} does not exist")
    try:
        text = p.read_text()
    except OSError as exc:
        raise ConfigError(f"{p}: cannot read {what} file: {exc.strerror or exc}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{p}: invalid TOML: {exc}") from None


def save_png(fig: Any, path: str | Path) -> Path:
    """Write a matplotlib figure as PNG (atomically) and close it."""
    import matplotlib.pyplot as plt  # the plot extra; only callers that made a figure get here

    out = Path(path)
    with atomic_write(out, "wb") as fh:
        fig.savefig(fh, format="png")
    plt.close(fig)
    return out

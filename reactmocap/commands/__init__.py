"""CLI sub-commands. Each module defines ``register(subparsers)``; parsing only, no algorithms."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path

__all__ = ["numbers", "output_dir", "output_file"]


def output_file(text: str) -> Path:
    """argparse type of an output file option: refuses a folder, or a place no file can be
    written, at parse time, not after a long simulation (``os.replace`` onto a folder fails
    only once everything is computed)."""
    path = Path(text)
    if path.is_dir() or text.endswith(("/", "\\")):
        raise argparse.ArgumentTypeError(
            f"{text!r} is a folder; give a file name (for example {str(path / 'out')!r} "
            "with the extension the option names)"
        )
    _check_writable(path)
    return path


def output_dir(text: str) -> Path:
    """argparse type of an output folder option: refuses a file, or a place no file can be
    written into, at parse time (not after the computation)."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file; give a folder")
    _check_writable(path / "out")
    return path


def numbers(count: int, form: str, units: str) -> Callable[[str], tuple[float, ...]]:
    """argparse type of an option of ``count`` finite numbers separated by commas, written
    ``form`` (``"X,Y"``) in ``units``: anything else is refused at parse time, naming both."""

    def parse(text: str) -> tuple[float, ...]:
        try:
            values = tuple(float(v) for v in text.split(","))
        except ValueError:
            values = ()
        if len(values) != count or not all(math.isfinite(v) for v in values):
            raise argparse.ArgumentTypeError(f"expected {form} ({units}), got {text!r}")
        return values

    return parse


def _check_writable(path: Path) -> None:
    from reactmocap.io import unwritable_reason

    why = unwritable_reason(path)
    if why is not None:
        raise argparse.ArgumentTypeError(why)

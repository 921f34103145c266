"""CLI sub-commands. Each module defines ``register(subparsers)``; parsing only, no algorithms."""

from __future__ import annotations

import argparse
from pathlib import Path


def output_file(text: str) -> Path:
    """argparse type of an output file option: refuses a folder at parse time, not after a
    long simulation (``os.replace`` onto a folder fails only once everything is computed)."""
    path = Path(text)
    if path.is_dir() or text.endswith(("/", "\\")):
        raise argparse.ArgumentTypeError(
            f"{text!r} is a folder; give a file name (for example {str(path / 'out')!r} "
            "with the extension the option names)"
        )
    return path

"""The ``reactmocap`` command: parse, call the Python API, print. Algorithms live elsewhere."""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Sequence

# MuJoCo picks its GL backend when it is imported: without a display, use EGL offscreen
# (``--video``); a user's own MUJOCO_GL wins.
if sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
    os.environ.setdefault("MUJOCO_GL", "egl")

from reactmocap import __version__
from reactmocap.errors import ReactMocapError

__all__ = ["build_parser", "main"]

# Modules under reactmocap.commands, each with register(subparsers). Order = help order.
COMMAND_MODULES = ("library", "search", "sim", "response", "batch", "athletics")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="reactmocap",
        description="Motion-capture characters that react physically to impacts.",
    )
    parser.add_argument("--version", action="version", version=f"reactmocap {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(f"reactmocap.commands.{name}").register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    func = getattr(args, "func", None)
    if func is None:
        parser.print_help()
        return 2
    try:
        return int(func(args) or 0)
    except ReactMocapError as exc:
        print(f"reactmocap: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("reactmocap: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())

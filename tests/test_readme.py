"""The README's command lines are accepted by the CLI's parser as written (run from the
repository root, as the README's commands are): an example that the parser refuses (an
``--out`` folder where a file is asked for, a renamed option) fails here, not for a user."""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest

from reactmocap.cli import build_parser

README = Path(__file__).resolve().parents[1] / "README.md"


def readme_commands() -> list[str]:
    """Each ``reactmocap ...`` command of the README's code lines (indented blocks, fenced
    shell blocks and ``&&`` chains), its ``# comment`` cut off."""
    found = []
    for line in README.read_text().splitlines():
        for part in line.split("&&"):
            words = part.split("#", 1)[0].strip()
            if words.startswith(".venv/bin/reactmocap "):  # the quick start's chain
                found.append(words[len(".venv/bin/reactmocap ") :])
            elif words.startswith("reactmocap ") and line.startswith("    "):  # code blocks
                found.append(words[len("reactmocap ") :])
    return found


def test_the_readme_has_commands() -> None:
    commands = readme_commands()
    assert len(commands) >= 15  # the quick start's demo and the athletics block at least
    assert any(c.startswith("demo") for c in commands)
    assert any(c.startswith("athletics handspring") for c in commands)


@pytest.mark.parametrize("command", readme_commands())
def test_the_readme_command_parses(
    command: str, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    # output options are checked for writability at parse time: a scratch copy of the
    # repository's relative layout is not needed, only a writable working folder
    monkeypatch.chdir(tmp_path)
    try:
        args = build_parser().parse_args(shlex.split(command))
    except SystemExit as e:  # argparse's refusal: its message went to stderr
        pytest.fail(f"README command refused by the parser (exit {e.code}): reactmocap {command}")
    assert args.command == command.split()[0]

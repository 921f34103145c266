"""Scenario files: defaults, located errors for bad fields, every shipped example validates."""

from __future__ import annotations

from pathlib import Path

import pytest

from reactmocap.errors import ConfigError
from reactmocap.response.scenario import ResponseConfig, load_scenario

REPO = Path(__file__).resolve().parents[2]

GOOD = """
library = "{lib}"
[recipient]
clip = "guard"
start = 0.5
facing_deg = 90
[impact]
body = "chest"
force = [-350, 0, 0]
at = 0.8
duration = 0.1
[response]
reaction_delay = 0.12
"""


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "s.toml"
    p.write_text(text.replace("{lib}", str(REPO / "data" / "synthetic_clips")))
    return p


def test_good_scenario_and_defaults(tmp_path: Path) -> None:
    s = load_scenario(write(tmp_path, GOOD))
    assert s.recipient.facing_deg == 90.0
    assert s.impact is not None and s.impact.force == (-350.0, 0.0, 0.0)
    assert s.response.reaction_delay == 0.12
    assert s.response.friction_sim1 == ResponseConfig().friction_sim1 == 1.0
    assert s.response.friction_sim2 == 0.5
    assert s.attacker is None


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ("facing_deg = 90", 'facing_deg = "north"'),
            r"\[recipient\].facing_deg: expected a number",
        ),
        (
            ("start = 0.5", "start = 0.5\ncolour = 3"),
            r"\[recipient\]: unknown key\(s\) \['colour'\]",
        ),
        (("force = [-350, 0, 0]", "force = [1, 2]"), r"\[impact\].force: expected a list of 3"),
        (("duration = 0.1", "duration = -1"), r"\[impact\].duration: expected a number > 0"),
        (("reaction_delay = 0.12", "reaction_delay = true"), r"reaction_delay: expected a number"),
        (
            ("reaction_delay = 0.12", "reaction_delay = 0.12\ntorque_limit = -5"),
            r"\[response\].torque_limit: expected a number >= 0",
        ),
        (
            ("reaction_delay = 0.12", "reaction_delay = 0.12\nblend_place = 1"),
            r"\[response\].blend_place: expected true or false",
        ),
        (('clip = "guard"', ""), r"\[recipient\]: missing required key\(s\) \['clip'\]"),
        (('library = "', 'library = "/nonexistent/'), r"library: .* not found"),
        (("[response]", "[responce]"), r"top level: unknown key\(s\) \['responce'\]"),
        (("force = [-350, 0, 0]", "force = [-350, 0, 0"), r"invalid TOML"),
    ],
)
def test_bad_fields_are_named(tmp_path: Path, edit: tuple[str, str], message: str) -> None:
    text = GOOD.replace(edit[0], edit[1], 1)
    with pytest.raises(ConfigError, match=message) as err:
        load_scenario(write(tmp_path, text))
    assert "s.toml" in str(err.value)


def test_needs_exactly_one_cause(tmp_path: Path) -> None:
    no_cause = GOOD.split("[impact]")[0]
    with pytest.raises(ConfigError, match="either an \\[attacker\\] or an \\[impact\\]"):
        load_scenario(write(tmp_path, no_cause))


@pytest.mark.parametrize(
    "path",
    sorted(p for p in (REPO / "examples").glob("*.toml") if not p.name.startswith("sweep")),
    ids=lambda p: p.name,
)
def test_examples_validate(path: Path) -> None:
    s = load_scenario(path)
    assert s.library.exists()

"""MuJoCo offscreen video of a response, and the stick-figure fallback without GL."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from reactmocap.library.synth import synthetic_clips
from reactmocap.response import pipeline
from reactmocap.response.render import RenderUnavailable, render_video
from reactmocap.response.scenario import load_scenario

iio = pytest.importorskip("imageio.v3")
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_render_video_draws_moving_characters(tmp_path: Path) -> None:
    clips = synthetic_clips(30.0)
    kick = clips["front_kick"].slice(0, 30)
    try:
        out = render_video(
            [(kick, (0.2, 0.4, 0.8, 1.0))],
            tmp_path / "v.mp4",
            ghost=(clips["guard"].slice(0, 30), (0.2, 0.8, 0.3, 0.3)),
        )
    except RenderUnavailable as exc:
        pytest.skip(f"no offscreen GL here: {exc}")
    frames = iio.imread(out)
    assert frames.shape == (kick.num_frames, 384, 512, 3)
    assert frames[0].std() > 5.0  # a scene, not a blank image
    # the kick moves: late frames differ from the first
    assert np.abs(frames[-1].astype(float) - frames[0].astype(float)).mean() > 0.5
    assert not list(tmp_path.glob(".*partial*"))


def test_video_falls_back_to_stick_figure_without_gl(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def no_gl(*args: object, **kwargs: object) -> Path:
        raise RenderUnavailable("no GL (test)")

    monkeypatch.setattr("reactmocap.response.render.render_video", no_gl)
    sc = load_scenario(EXAMPLES / "light_push.toml")
    report = pipeline.run_scenario(sc, tmp_path, video=True)
    assert report["outputs"]["video"].endswith("video.gif")
    assert "stick figure" in report["outputs"]["video_renderer"]
    saved = json.loads((tmp_path / "report.json").read_text())
    assert saved["outputs"]["video"] == report["outputs"]["video"]
    assert iio.imread(tmp_path / "video.gif").shape[0] > 10

"""Runners on the real response pipeline: pool and Ray agree, failures are isolated, worker
crashes are retried once, and the figures draw from the results."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from reactmocap.batch import load_sweep, run_batch
from reactmocap.cli import main

from . import fake_tasks


def _without_timings(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    return {r["id"]: {k: v for k, v in r.items() if not k.startswith("time_")} for r in rows}


@pytest.fixture(scope="module")
def ray_runtime(warm_cache: Path):  # type: ignore[no-untyped-def]
    """The real Ray runtime, local. Its workers inherit the environment at ray.init, which
    runs before the per-test cache folder is set, so set it here: otherwise Ray workers read
    the user's cache and may compute with an index built by older code."""
    ray = pytest.importorskip("ray")
    mp = pytest.MonkeyPatch()
    mp.setenv("REACTMOCAP_CACHE_DIR", str(warm_cache))
    ray.init(num_cpus=2, include_dashboard=False, logging_level="WARNING")
    yield ray
    ray.shutdown()
    mp.undo()


def test_pool_and_ray_give_identical_rows(warm_cache, write_sweep, tmp_path, ray_runtime) -> None:  # type: ignore[no-untyped-def]
    sweep = load_sweep(write_sweep("facing_deg = [0, 90, 180, 270]"))
    pool = run_batch(sweep, tmp_path / "pool", runner="local", workers=2, progress=False)
    ray = run_batch(sweep, tmp_path / "ray", runner="ray", workers=2, progress=False)
    assert pool.ran == ray.ran == 4
    assert [r["status"] for r in pool.rows] == ["ok"] * 4, pool.rows
    a, b = _without_timings(pool.rows), _without_timings(ray.rows)
    assert a == b, [(k, x, b[i][k]) for i, r in a.items() for k, x in r.items() if b[i][k] != x]
    assert all(r["time_total_s"] > 0 for r in ray.rows)
    # the CSVs carry the same rows in the same (grid) order
    pool_csv = (tmp_path / "pool" / "results.csv").read_text().splitlines()
    ray_csv = (tmp_path / "ray" / "results.csv").read_text().splitlines()
    assert len(pool_csv) == len(ray_csv) == 5
    assert [ln.split(",")[:10] for ln in pool_csv] == [ln.split(",")[:10] for ln in ray_csv]


def test_failing_scenario_is_recorded_and_others_complete(
    warm_cache, write_sweep, tmp_path, capsys
) -> None:  # type: ignore[no-untyped-def]
    sweep = load_sweep(write_sweep('facing_deg = [0, 90]\nattacker_clip = ["front_kick", "nope"]'))
    out = tmp_path / "out"
    res = run_batch(sweep, out, workers=2, save_animations=True, progress=False)
    by_clip = {(r["facing_deg"], r["attacker_clip"]): r for r in res.rows}
    assert len(by_clip) == 4
    for facing in (0.0, 90.0):
        bad, good = by_clip[(facing, "nope")], by_clip[(facing, "front_kick")]
        assert bad["status"] == "error" and "nope" in bad["error"] and bad["matched_clip"] is None
        assert good["status"] == "ok" and good["error"] is None and good["matched_clip"]
        assert (out / good["output_dir"] / "recipient.bvh").is_file()
        report = json.loads((out / good["output_dir"] / "report.json").read_text())
        assert report["matched"]["clip"] == good["matched_clip"]
    assert res.summary.count == 4 and res.summary.failures == 2
    # a rerun skips failures too unless asked to retry them
    again = run_batch(sweep, out, workers=1, progress=False)
    assert again.ran == 0 and again.skipped == 4
    # figures: one per axis, and the contact sheet from the saved animations
    assert main(["batch", "plot", str(out)]) == 0
    written = {Path(ln).name for ln in capsys.readouterr().out.split()}
    assert written == {"plot_facing_deg.png", "plot_attacker_clip.png", "contact_sheet.png"}
    assert all((out / n).stat().st_size > 1000 for n in written)


def test_pool_worker_crash_is_retried_once_then_recorded(write_sweep, tmp_path) -> None:  # type: ignore[no-untyped-def]
    sweep = load_sweep(write_sweep("facing_deg = [0, 45, 90, 135, 180]"))
    res = run_batch(sweep, tmp_path / "o", workers=2, task=fake_tasks.crash_at_90, progress=False)
    status = {r["facing_deg"]: (r["status"], r["error"]) for r in res.rows}
    assert len(status) == 5
    assert status[90.0][0] == "error" and "WorkerCrashed" in status[90.0][1]
    # innocent scenarios that shared the broken pool were rerun and succeeded
    assert all(status[f] == ("ok", None) for f in (0.0, 45.0, 135.0, 180.0)), status


def test_ray_worker_crash_is_retried_once_then_recorded(write_sweep, tmp_path, ray_runtime) -> None:  # type: ignore[no-untyped-def]
    from ray import cloudpickle  # the copy Ray pickles tasks with (no separate package)

    cloudpickle.register_pickle_by_value(fake_tasks)  # Ray workers need not import tests/
    try:
        sweep = load_sweep(write_sweep("facing_deg = [0, 90]"))
        res = run_batch(
            sweep, tmp_path / "o", runner="ray", task=fake_tasks.crash_at_90, progress=False
        )
    finally:
        cloudpickle.unregister_pickle_by_value(fake_tasks)
    status = {r["facing_deg"]: r for r in res.rows}
    assert status[0.0]["status"] == "ok"
    assert status[90.0]["status"] == "error"
    assert "WorkerCrashed" in status[90.0]["error"] and "retried once" in status[90.0]["error"]


def test_results_folder_refuses_another_base(write_sweep, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    from reactmocap.errors import ConfigError

    from .conftest import EXAMPLES

    a = load_sweep(write_sweep("facing_deg = [0]"))
    run_batch(a, tmp_path / "o", runner="serial", task=fake_tasks.fake_report, progress=False)
    b = load_sweep(write_sweep("facing_deg = [0]", base=EXAMPLES / "side_kick_chest.toml"))
    with pytest.raises(ConfigError, match="different base scenario"):
        run_batch(b, tmp_path / "o", runner="serial", task=fake_tasks.fake_report, progress=False)


@pytest.mark.parametrize("workers", [0, -3])
def test_workers_below_one_are_refused_before_anything_runs(
    write_sweep, tmp_path: Path, workers: int
) -> None:  # type: ignore[no-untyped-def]
    from reactmocap.errors import ConfigError

    sweep = load_sweep(write_sweep("facing_deg = [0]"))
    with pytest.raises(ConfigError, match=f"workers must be an integer >= 1 .*got {workers}"):
        run_batch(
            sweep, tmp_path / "o", workers=workers, task=fake_tasks.fake_report, progress=False
        )
    assert not (tmp_path / "o").exists()

"""Running a sweep: the per-scenario job, the runners (a local process pool, Ray, in-process)
and :func:`run_batch`, which makes a run resumable and interrupt-safe.

Every runner is a generator ``runner(points, job, workers, address)`` yielding one result row per
point as it completes; :func:`run_batch` appends each row to ``results.jsonl`` at once, so
whatever finished before a crash or Ctrl-C is kept and a rerun skips it.
"""

from __future__ import annotations

import contextlib
import json
import logging
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Generator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any

from reactmocap import __version__
from reactmocap.batch.results import (
    ResultStore,
    Summary,
    error_row,
    format_summary,
    report_row,
    summarize,
)
from reactmocap.batch.sweep import Sweep, SweepPoint
from reactmocap.errors import ConfigError, ReactMocapError, UnknownKeyError
from reactmocap.io import atomic_write_text
from reactmocap.progress import Progress

__all__ = ["RUNNERS", "BatchResult", "Job", "describe", "get_runner", "run_batch", "versions"]

Rows = Generator[dict[str, Any], None, None]
#: ``task(scenario, out_dir)`` -> report; the default is the real response pipeline
Task = Callable[..., Mapping[str, Any]]
Runner = Callable[[Sequence[SweepPoint], "Job", int, "str | None"], Rows]
#: submissions kept in flight per worker: enough to keep workers busy, few enough that Ctrl-C
#: stops the batch without a long queue to cancel
IN_FLIGHT_PER_WORKER = 2


@dataclass(frozen=True)
class Job:
    """What a worker does with one sweep point. Picklable: it travels to pool and Ray workers,
    where it keeps one :class:`~reactmocap.response.library_cache.LibraryCache` for all the
    points it runs (the cache itself never travels). Any exception of the scenario becomes an
    error row, so one bad scenario never stops a batch."""

    out_dir: str | None = None  # the batch folder when per-scenario outputs are saved
    task: Task | None = None  # None: reactmocap.response.pipeline.run_scenario

    def __call__(self, point: SweepPoint) -> dict[str, Any]:
        rel = f"scenarios/{point.id}" if self.out_dir is not None else None
        try:
            out = Path(self.out_dir) / rel if self.out_dir is not None and rel else None
            if self.task is not None:
                report = self.task(point.scenario, out)
            else:
                report = _pipeline()(point.scenario, out, cache=self._cache())
        except Exception as exc:  # isolation is the point
            return error_row(point.id, point.params, f"{type(exc).__name__}: {exc}", rel)
        return report_row(point.id, point.params, report, rel)

    def _cache(self) -> Any:
        cache = self.__dict__.get("_library_cache")
        if cache is None:
            from reactmocap.response.library_cache import LibraryCache

            cache = LibraryCache()
            object.__setattr__(self, "_library_cache", cache)
        return cache

    def __getstate__(self) -> dict[str, Any]:
        return {k: v for k, v in self.__dict__.items() if k != "_library_cache"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)


def _pipeline() -> Task:
    from reactmocap.response.pipeline import run_scenario  # imported in the worker, lazily

    return run_scenario


# ----------------------------------------------------------------------------- runners
def run_serial(
    points: Sequence[SweepPoint], job: Job, workers: int = 1, address: str | None = None
) -> Rows:
    """In this process, one after another (debugging, tests, tiny sweeps)."""
    for p in points:
        yield job(p)


def _new_pool(workers: int) -> ProcessPoolExecutor:
    ctx = multiprocessing.get_context("spawn")
    return ProcessPoolExecutor(
        workers, mp_context=ctx, initializer=_init_worker, initargs=(os.getpid(),)
    )


def _init_worker(parent: int) -> None:
    # A terminal's Ctrl-C reaches the whole process group: only the parent should act on it
    # (it stops the workers itself), or every idle worker dies printing a traceback.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # A pool worker outlives a hard-killed parent (its queue pipe stays open) and would go on
    # burning a core on queued scenarios whose rows nobody writes: leave when orphaned.
    threading.Thread(target=_exit_when_orphaned, args=(parent,), daemon=True).start()


def _exit_when_orphaned(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(0.5)
    os._exit(1)


def _crashed(p: SweepPoint, job: Job, why: str) -> dict[str, Any]:
    rel = f"scenarios/{p.id}" if job.out_dir is not None else None
    return error_row(p.id, p.params, f"WorkerCrashed: {why} (retried once)", rel)


def run_local(
    points: Sequence[SweepPoint], job: Job, workers: int = 1, address: str | None = None
) -> Rows:
    """A local process pool of ``workers`` processes.

    'spawn' workers: forking a parent that holds MuJoCo/OpenMP/BLAS threads can deadlock. A worker
    crash breaks the whole pool and fails every task in flight, so those points are retried
    afterwards one at a time in a fresh pool: an innocent point then succeeds, and a point that
    crashes its worker again is recorded as an error.
    """
    todo = deque(points)
    suspects: list[SweepPoint] = []
    pool = _new_pool(workers)
    inflight: dict[Future[dict[str, Any]], SweepPoint] = {}
    clean = False
    try:
        while todo or inflight:
            submit_failed = False
            while todo and len(inflight) < IN_FLIGHT_PER_WORKER * workers:
                p = todo.popleft()
                try:
                    inflight[pool.submit(job, p)] = p
                except BrokenProcessPool:  # a worker died between the last wait and now
                    todo.appendleft(p)
                    submit_failed = True
                    break
            done, _ = wait(inflight, return_when=FIRST_COMPLETED)
            broke = submit_failed or any(isinstance(f.exception(), BrokenProcessPool) for f in done)
            if broke:
                wait(inflight)  # a broken pool resolves every pending future promptly
                done = set(inflight)
            for f in done:
                p = inflight.pop(f)
                if isinstance(f.exception(), BrokenProcessPool):
                    suspects.append(p)
                else:
                    yield _result(f, p, job)
            if broke:
                pool.shutdown(wait=True)
                pool = _new_pool(workers)
        for p in suspects:  # one at a time, so a crash is pinned on the point that caused it
            f = pool.submit(job, p)
            wait([f])
            if isinstance(f.exception(), BrokenProcessPool):
                yield _crashed(p, job, "the worker process died")
                pool.shutdown(wait=True)
                pool = _new_pool(workers)
            else:
                yield _result(f, p, job)
        clean = True
    finally:
        _stop(pool, clean)


def _result(f: Future[dict[str, Any]], p: SweepPoint, job: Job) -> dict[str, Any]:
    exc = f.exception()
    if exc is None:
        return f.result()
    if isinstance(exc, KeyboardInterrupt):  # the worker got the terminal's Ctrl-C too
        raise KeyboardInterrupt
    rel = f"scenarios/{p.id}" if job.out_dir is not None else None
    return error_row(p.id, p.params, f"{type(exc).__name__}: {exc}", rel)  # e.g. unpicklable


def _stop(pool: ProcessPoolExecutor, clean: bool) -> None:
    if clean:
        pool.shutdown(wait=True)
        return
    # Interrupted: drop queued work and end running scenarios now instead of waiting for them
    # (their rows would be lost anyway; a rerun redoes them). No public API for this.
    procs = list(getattr(pool, "_processes", {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in procs:
        with contextlib.suppress(Exception):
            proc.terminate()


def _ray_call(job: Job, point: SweepPoint) -> dict[str, Any]:
    return job(point)


def run_ray(
    points: Sequence[SweepPoint], job: Job, workers: int = 1, address: str | None = None
) -> Rows:
    """Ray tasks: a local runtime with ``workers`` CPUs, or the cluster at ``address``
    (``"auto"`` or ``host:port``). Reuses a runtime the caller already started. Ray retries a
    task whose worker died once (``max_retries=1``); a second death is recorded."""
    try:
        import ray
        import ray.exceptions
    except ImportError:
        raise ReactMocapError("the Ray runner needs ray: pip install 'reactmocap[ray]'") from None
    started = not ray.is_initialized()
    if started:
        opts: dict[str, Any] = {"include_dashboard": False, "logging_level": logging.WARNING}
        if address:
            ray.init(address=address, **opts)
        else:
            ray.init(num_cpus=workers, **opts)
    refs: dict[Any, SweepPoint] = {}
    try:
        capacity = max(1, int(ray.cluster_resources().get("CPU", workers)))
        remote = ray.remote(num_cpus=1, max_retries=1, retry_exceptions=False)(_ray_call)
        job_ref = ray.put(job)
        todo = deque(points)
        while todo or refs:
            while todo and len(refs) < IN_FLIGHT_PER_WORKER * capacity:
                p = todo.popleft()
                refs[remote.remote(job_ref, p)] = p
            ready, _ = ray.wait(list(refs), num_returns=1)
            for ref in ready:
                p = refs.pop(ref)
                try:
                    row = ray.get(ref)
                except (ray.exceptions.WorkerCrashedError, ray.exceptions.NodeDiedError) as exc:
                    row = _crashed(p, job, f"{type(exc).__name__}: {exc}")
                except ray.exceptions.RayError as exc:  # e.g. a result that does not unpickle
                    row = error_row(
                        p.id,
                        p.params,
                        f"{type(exc).__name__}: {exc}",
                        f"scenarios/{p.id}" if job.out_dir else None,
                    )
                yield row
    finally:
        for ref in refs:
            with contextlib.suppress(Exception):
                ray.cancel(ref, force=True)
        if started:
            ray.shutdown()


RUNNERS: dict[str, Runner] = {"local": run_local, "ray": run_ray, "serial": run_serial}


def get_runner(name: str) -> Runner:
    try:
        return RUNNERS[name]
    except KeyError:
        raise UnknownKeyError(
            f"unknown runner {name!r}; valid runners are {sorted(RUNNERS)}"
        ) from None


# ----------------------------------------------------------------------------- driver
def versions() -> dict[str, str]:
    try:
        mj = metadata.version("mujoco")
    except metadata.PackageNotFoundError:
        mj = "unknown"
    return {"reactmocap": __version__, "mujoco": mj}


@dataclass(frozen=True)
class BatchResult:
    out_dir: Path
    rows: list[dict[str, Any]]  # one per sweep point, grid order (those done so far)
    ran: int  # scenarios run by this call
    skipped: int  # already in results.jsonl
    summary: Summary


def _check_meta(out: Path, sweep: Sweep, log: Callable[[str], None]) -> None:
    """``DIR/sweep.json`` ties a results folder to one base scenario: rows of another base
    would silently mix with these, since ids only hash the swept parameters."""
    meta_path = out / "sweep.json"
    meta = {
        "name": sweep.name,
        "source": sweep.source,
        "base_fingerprint": sweep.fingerprint(),
        "axes": {k: list(v) for k, v in sweep.axes.items()},
        "versions": versions(),
    }
    if meta_path.exists():
        try:
            old = json.loads(meta_path.read_text())
        except (OSError, ValueError):
            old = {}
        if old.get("base_fingerprint") not in (None, meta["base_fingerprint"]):
            raise ConfigError(
                f"{out} holds results of a different base scenario than {sweep.source}; "
                "use another --out folder (ids hash only the swept parameters)"
            )
        if old.get("versions") not in (None, meta["versions"]):
            log(f"note: {out} was started with {old['versions']}, resuming with {meta['versions']}")
    atomic_write_text(meta_path, json.dumps(meta, indent=2) + "\n")


def run_batch(
    sweep: Sweep,
    out_dir: str | Path,
    *,
    runner: str = "local",
    workers: int | None = None,
    address: str | None = None,
    save_animations: bool = False,
    retry_failed: bool = False,
    task: Task | None = None,
    progress: bool = True,
    log: Callable[[str], None] | None = None,
) -> BatchResult:
    """Run every point of ``sweep`` not yet in ``out_dir/results.jsonl`` and regenerate
    ``results.csv``. Interrupts (Ctrl-C) propagate after the CSV is rewritten from the rows done.
    ``task`` replaces the response pipeline (tests of the batch machinery)."""
    run_fn = get_runner(runner)
    say = log if log is not None else (lambda s: print(s, file=sys.stderr))
    if workers is not None and not (isinstance(workers, int) and workers >= 1):
        raise ConfigError(f"workers must be an integer >= 1 (None: the CPU count), got {workers!r}")
    workers = workers or os.cpu_count() or 1
    out = Path(out_dir)
    points = sweep.points()  # validates every point before anything runs
    out.mkdir(parents=True, exist_ok=True)
    _check_meta(out, sweep, say)
    store = ResultStore(out)
    done = store.load()
    redo = {"ok"} if retry_failed else {"ok", "error"}
    todo = [p for p in points if done.get(p.id, {}).get("status") not in redo]
    say(
        f"{sweep.name}: {len(points)} scenarios, {len(points) - len(todo)} already done, "
        f"running {len(todo)} on {runner} ({workers} worker{'s' * (workers != 1)})"
    )
    job = Job(str(out.resolve()) if save_animations else None, task)
    ran = 0
    gen = run_fn(todo, job, workers, address) if todo else run_serial([], job)  # no Ray start
    try:
        with Progress(len(todo), sweep.name, force=False) if progress else _NoBar() as bar:
            for row in gen:
                store.append(row)
                ran += 1
                bar.update()
    finally:
        gen.close()  # stops the workers when interrupted
        store.close()
        rows = store.write_csv([p.id for p in points], list(sweep.axes))
    ids = {p.id for p in points}
    mine = [r for r in rows if r["id"] in ids]
    return BatchResult(out, mine, ran, len(points) - len(todo), summarize(mine))


class _NoBar:
    def __enter__(self) -> _NoBar:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def update(self, n: int = 1) -> None:
        return None


def describe(result: BatchResult) -> str:
    """The end-of-batch summary table."""
    return f"{format_summary(result.summary)}\nresults: {result.out_dir / 'results.csv'}"

"""Resume: a sweep killed midway (hard, then with SIGINT) and rerun ends with exactly one row per
scenario, and no file is ever half-written."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from reactmocap.batch import ResultStore

from .conftest import REPO

N = 12


def _lines(p: Path) -> list[str]:
    try:
        return p.read_text().splitlines()
    except FileNotFoundError:
        return []


def _start(sweep: Path, out: Path) -> subprocess.Popen[str]:
    cmd = [
        sys.executable,
        "-m",
        "reactmocap",
        "batch",
        str(sweep),
        "--out",
        str(out),
        "--workers",
        "1",
    ]
    # the sweep must get Ctrl-C's default handling even when this process ignores SIGINT (an
    # ignored signal stays ignored across exec, and Python then installs no KeyboardInterrupt)
    return subprocess.Popen(
        cmd,
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_default_sigint,
    )


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _run_until(proc: subprocess.Popen[str], jsonl: Path, rows: int, sig: int) -> None:
    deadline = time.monotonic() + 90
    while len(_lines(jsonl)) < rows:
        assert proc.poll() is None, f"finished before it could be interrupted: {proc.communicate()}"
        assert time.monotonic() < deadline, "sweep made no progress"
        time.sleep(0.02)
    proc.send_signal(sig)


def _children(pid: int) -> list[int]:
    kids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == pid:
            kids.append(int(stat.parent.name))
    return kids


def _assert_gone(pids: list[int], timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while any(Path(f"/proc/{p}").exists() for p in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    alive = [p for p in pids if Path(f"/proc/{p}").exists()]
    for p in alive:  # do not leak them into the rest of the session
        os.kill(p, signal.SIGKILL)
    assert not alive, f"pool workers {alive} outlived their killed parent"


def test_killed_sweep_resumes_with_exact_rows(warm_cache, write_sweep, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    angles = ", ".join(str(a) for a in range(0, 360, 360 // N))
    sweep = write_sweep(f"facing_deg = [{angles}]")
    out = tmp_path / "out"
    jsonl = out / "results.jsonl"

    # 1. hard kill: no cleanup at all; then a torn last line as if killed inside a write
    proc = _start(sweep, out)
    _run_until(proc, jsonl, 2, signal.SIGKILL)
    workers = _children(proc.pid)
    proc.wait(timeout=30)
    _assert_gone(workers)  # orphaned pool workers leave instead of running on
    first = len(_lines(jsonl))
    assert 2 <= first < N
    with jsonl.open("a") as fh:
        fh.write('{"id": "torn-li')

    # 2. SIGINT (Ctrl-C): finished rows kept, results.csv rewritten from them, exit 130
    proc = _start(sweep, out)
    _run_until(proc, jsonl, first + 2, signal.SIGINT)
    out_text, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, (err, out_text, signal.getsignal(signal.SIGINT))
    assert f"{first} already done" in err and "interrupted" in err and "Traceback" not in err
    second = [json.loads(ln) for ln in _lines(jsonl)]  # every line whole, torn one gone
    assert first + 2 <= len(second) < N
    csv_rows = _lines(out / "results.csv")[1:]
    assert len(csv_rows) == len(second)

    # 3. rerun to the end: exactly N rows, no duplicate ids, nothing left behind
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "reactmocap",
            "batch",
            str(sweep),
            "--out",
            str(out),
            "--workers",
            "1",
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert f"{len(second)} already done, running {N - len(second)}" in done.stderr
    rows = [json.loads(ln) for ln in _lines(jsonl)]
    assert len(rows) == N and len({r["id"] for r in rows}) == N
    assert all(r["status"] == "ok" for r in rows)
    assert len(_lines(out / "results.csv")) == N + 1
    assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")]
    assert f"{N} scenarios, 0 failed" in done.stdout


def test_store_truncates_a_torn_line_and_keeps_the_last_row_per_id(tmp_path: Path) -> None:
    store = ResultStore(tmp_path)
    store.append({"id": "a", "status": "error", "error": "x"})
    store.append({"id": "b", "status": "ok"})
    store.append({"id": "a", "status": "ok"})  # a --retry-failed rerun supersedes
    store.close()
    with store.jsonl.open("ab") as fh:
        fh.write(b'{"id": "c", "sta')
    rows = store.load()
    assert list(rows) == ["a", "b"] and rows["a"]["status"] == "ok"
    assert store.jsonl.read_bytes().endswith(b"}\n")
    written = store.write_csv(order=["b", "a"])
    assert [r["id"] for r in written] == ["b", "a"]
    assert os.path.getsize(store.csv) > 0

"""BVH read/write with bulk numpy conversion of the frames.

The hierarchy is tokenised here with line numbers so that every problem is reported as a
:class:`BVHParseError` with file, line and what was expected (the ``bvh`` package keeps no line
numbers and walks frames in Python); the resulting tree is cross-checked with ``bvh.Bvh`` for
joint names, parents and channels. The MOTION block is converted in one ``np.array`` call.

Conventions: a file is Y-up unless ``up="z"``; its length unit is detected from the body's
span (``detect_unit``) unless ``unit=`` is given. Internally everything is Z-up metres with wxyz
quaternions; writing converts back to the source layout recorded in ``Skeleton.layout``.
Position channels on the root give its position; on other joints they replace the offset.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from reactmocap.conventions import UNIT_SCALE, UpAxis, axes_to_z_up, detect_unit
from reactmocap.errors import BVHParseError, MotionError
from reactmocap.io import atomic_write_text
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import (
    POSITION_CHANNELS,
    ROTATION_CHANNELS,
    VALID_CHANNELS,
    BVHLayout,
    Skeleton,
)
from reactmocap.rotations import quat_from_euler, quat_mul, quat_rotate, quat_to_euler

__all__ = ["bvh_text", "parse_bvh", "read_bvh", "write_bvh"]

F64 = NDArray[np.float64]


@dataclass
class _Joint:
    name: str
    parent: int
    offset: tuple[float, float, float]
    channels: tuple[str, ...] = ()
    end_site: tuple[float, float, float] | None = None
    line: int = 0


@dataclass
class _Tokens:
    items: list[tuple[str, int]]
    file: str
    pos: int = 0
    joints: list[_Joint] = field(default_factory=list)

    def peek(self) -> tuple[str, int]:
        if self.pos >= len(self.items):
            last = self.items[-1][1] if self.items else 1
            raise BVHParseError("unexpected end of file", file=self.file, line=last,
                                expected="more of the HIERARCHY")  # fmt: skip
        return self.items[self.pos]

    def take(self, expected: str | None = None) -> tuple[str, int]:
        tok, line = self.peek()
        if expected is not None and tok != expected:
            raise BVHParseError(f"found {tok!r}", file=self.file, line=line,
                                expected=repr(expected))  # fmt: skip
        self.pos += 1
        return tok, line

    def number(self, what: str) -> float:
        tok, line = self.take()
        try:
            v = float(tok)
        except ValueError:
            raise BVHParseError(f"non-numeric token {tok!r} in {what}", file=self.file,
                                line=line, expected="a number") from None  # fmt: skip
        if not math.isfinite(v):
            raise BVHParseError(f"{tok} in {what}", file=self.file, line=line,
                                expected="a finite number")  # fmt: skip
        return v


def _parse_joint(tk: _Tokens, parent: int) -> None:
    kw, line = tk.take()
    name, _ = tk.take()
    idx = len(tk.joints)
    if any(j.name == name for j in tk.joints):
        raise BVHParseError(f"duplicate joint name {name!r}", file=tk.file, line=line,
                            expected="unique joint names")  # fmt: skip
    tk.take("{")
    tk.take("OFFSET")
    off = (tk.number("OFFSET"), tk.number("OFFSET"), tk.number("OFFSET"))
    joint = _Joint(name, parent, off, line=line)
    tk.joints.append(joint)
    tok, line = tk.peek()
    if tok == "CHANNELS":
        tk.take()
        count_tok, cl = tk.take()
        if not count_tok.isdigit():
            raise BVHParseError(f"channel count {count_tok!r}", file=tk.file, line=cl,
                                expected="an integer channel count")  # fmt: skip
        chans = []
        for _ in range(int(count_tok)):
            c, cl = tk.take()
            if c not in VALID_CHANNELS:
                raise BVHParseError(f"unknown channel name {c!r}", file=tk.file, line=cl,
                                    expected=f"one of {list(VALID_CHANNELS)}")  # fmt: skip
            chans.append(c)
        rot = [c for c in chans if c in ROTATION_CHANNELS]
        if rot and len(rot) != 3:
            raise BVHParseError(f"joint {name!r} has {len(rot)} rotation channels", file=tk.file,
                                line=cl, expected="0 or 3 rotation channels")  # fmt: skip
        joint.channels = tuple(chans)
    while True:
        tok, line = tk.peek()
        if tok == "}":
            tk.take()
            return
        if tok == "JOINT":
            _parse_joint(tk, idx)
        elif tok == "End":
            tk.take()
            tk.take("Site")
            tk.take("{")
            tk.take("OFFSET")
            joint.end_site = (tk.number("OFFSET"), tk.number("OFFSET"), tk.number("OFFSET"))
            tk.take("}")
        else:
            raise BVHParseError(f"found {tok!r} in joint {name!r}", file=tk.file, line=line,
                                expected="JOINT, End Site or '}'")  # fmt: skip


def parse_bvh(
    text: str,
    *,
    file: str | Path = "<string>",
    unit: str | None = None,
    up: UpAxis = "y",
    name: str | None = None,
) -> Motion:
    """Parse BVH text into a Motion (Z-up metres, wxyz)."""
    fname = str(file)
    lines = text.splitlines()
    try:
        h_line = next(i for i, s in enumerate(lines) if s.strip())
    except StopIteration:
        raise BVHParseError("empty file", file=fname, line=1, expected="HIERARCHY") from None
    if lines[h_line].strip() != "HIERARCHY":
        raise BVHParseError(f"found {lines[h_line].strip()[:40]!r}", file=fname,
                            line=h_line + 1, expected="HIERARCHY")  # fmt: skip
    m_line = next((i for i, s in enumerate(lines) if s.strip() == "MOTION"), None)
    if m_line is None:
        raise BVHParseError("no MOTION section", file=fname, line=len(lines),
                            expected="MOTION after the hierarchy")  # fmt: skip
    items = [(tok, i + 1) for i in range(h_line + 1, m_line) for tok in lines[i].split()]
    tk = _Tokens(items, fname)
    if not items or items[0][0] != "ROOT":
        raise BVHParseError("no ROOT joint", file=fname, line=h_line + 2, expected="ROOT")
    _parse_joint(tk, -1)
    if tk.pos != len(items):
        tok, line = items[tk.pos]
        raise BVHParseError(f"found {tok!r} after the root joint", file=fname, line=line,
                            expected="MOTION")  # fmt: skip
    joints = tk.joints

    # MOTION header
    def header(k: int, key: str) -> str:
        if k >= len(lines):
            raise BVHParseError("file ends in the MOTION header", file=fname, line=len(lines),
                                expected=key)  # fmt: skip
        s = lines[k].strip()
        if not s.startswith(key):
            raise BVHParseError(f"found {s[:40]!r}", file=fname, line=k + 1, expected=key)
        return s[len(key):].strip()

    frames_txt = header(m_line + 1, "Frames:")
    ft_txt = header(m_line + 2, "Frame Time:")
    try:
        n_frames = int(frames_txt)
    except ValueError:
        raise BVHParseError(f"Frames: {frames_txt!r}", file=fname, line=m_line + 2,
                            expected="an integer frame count") from None  # fmt: skip
    if n_frames <= 0:
        raise BVHParseError(f"Frames: {n_frames}", file=fname, line=m_line + 2,
                            expected="at least one frame")  # fmt: skip
    try:
        frame_time = float(ft_txt)
    except ValueError:
        raise BVHParseError(f"Frame Time: {ft_txt!r}", file=fname, line=m_line + 3,
                            expected="a number of seconds") from None  # fmt: skip
    if not (math.isfinite(frame_time) and frame_time > 0):
        raise BVHParseError(f"Frame Time: {ft_txt}", file=fname, line=m_line + 3,
                            expected="a positive number of seconds")  # fmt: skip
    n_ch = sum(len(j.channels) for j in joints)
    first = m_line + 3
    rows = [(i, s) for i, s in enumerate(lines[first:], start=first) if s.strip()]
    if len(rows) < n_frames:
        line = rows[-1][0] + 2 if rows else first + 1
        raise BVHParseError(f"truncated motion: {len(rows)} frame lines for Frames: {n_frames}",
                            file=fname, line=line, expected=f"{n_frames} frame lines")  # fmt: skip
    if len(rows) > n_frames:
        raise BVHParseError(f"{len(rows) - n_frames} frame lines beyond Frames: {n_frames}",
                            file=fname, line=rows[n_frames][0] + 1,
                            expected=f"{n_frames} frame lines")  # fmt: skip
    split = [s.split() for _, s in rows]
    counts = np.fromiter((len(x) for x in split), dtype=np.int64, count=len(split))
    bad = np.flatnonzero(counts != n_ch)
    if bad.size:
        k = int(bad[0])
        raise BVHParseError(f"frame line has {counts[k]} values", file=fname,
                            line=rows[k][0] + 1, expected=f"{n_ch} values")  # fmt: skip
    try:
        data = np.array(split, dtype=np.float64).reshape(n_frames, n_ch)
    except ValueError:
        for k, toks in enumerate(split):
            for tok in toks:
                try:
                    float(tok)
                except ValueError:
                    raise BVHParseError(f"non-numeric token {tok!r}", file=fname,
                                        line=rows[k][0] + 1, expected="a number") from None  # fmt: skip
        raise
    if not np.all(np.isfinite(data)):
        k = int(np.flatnonzero(~np.all(np.isfinite(data), axis=1))[0])
        raise BVHParseError("NaN or inf value", file=fname, line=rows[k][0] + 1,
                            expected="finite numbers")  # fmt: skip
    _cross_check(text, joints, fname)
    return _to_motion(joints, data, 1.0 / frame_time, unit, up, name or Path(fname).stem, fname)


def _cross_check(text: str, joints: list[_Joint], fname: str) -> None:
    """Agree with the ``bvh`` package on names, parents and channels (guards our tokeniser)."""
    try:
        from bvh import Bvh

        ref = Bvh(text.split("MOTION")[0] + "MOTION\nFrames: 0\nFrame Time: 1\n")
        names = ref.get_joints_names()
    except Exception:  # the package chokes on some valid files; our parser already validated
        return
    if names != [j.name for j in joints]:
        raise BVHParseError("hierarchy read inconsistently", file=fname, line=1,
                            expected=f"joints {names}")  # fmt: skip


def _to_motion(
    joints: list[_Joint], data: F64, fps: float, unit: str | None, up: UpAxis, name: str,
    fname: str,
) -> Motion:  # fmt: skip
    t = data.shape[0]
    nj = len(joints)
    offsets_f = np.array([j.offset for j in joints])
    parents = np.array([j.parent for j in joints])
    euler = np.zeros((t, nj, 3))
    trans_f = np.broadcast_to(offsets_f, (t, nj, 3)).copy()
    has_pos = np.zeros(nj, dtype=bool)
    col = 0
    orders = []
    for k, j in enumerate(joints):
        order = "".join(c[0] for c in j.channels if c in ROTATION_CHANNELS) or "ZXY"
        orders.append(order)
        r = 0
        for c in j.channels:
            if c in POSITION_CHANNELS:
                trans_f[:, k, "XYZ".index(c[0])] = data[:, col]
                has_pos[k] = True
            else:
                euler[:, k, r] = data[:, col]
                r += 1
            col += 1
    # local rotations in file axes, joint by joint (orders may differ)
    rot_f = np.empty((t, nj, 4))
    for order in set(orders):
        idx = [k for k, o in enumerate(orders) if o == order]
        rot_f[:, idx] = quat_from_euler(np.radians(euler[:, idx]), order)
    if unit is None:
        unit = detect_unit(_span(parents, trans_f[: min(t, 10)], rot_f[: min(t, 10)]))
    if unit not in UNIT_SCALE:
        raise BVHParseError(f"unit {unit!r}", file=fname, expected=f"one of {list(UNIT_SCALE)}")
    scale = UNIT_SCALE[unit]
    a = axes_to_z_up(up)
    qa = _axes_quat(a)
    rot = quat_mul(quat_mul(qa, rot_f), qa * np.array([1, -1, -1, -1]))
    trans = trans_f @ a.T * scale
    offsets = offsets_f @ a.T * scale
    sites = {k: tuple(float(x) for x in (np.array(j.end_site) @ a.T * scale))
             for k, j in enumerate(joints) if j.end_site is not None}  # fmt: skip
    layout = BVHLayout(tuple(j.channels for j in joints), unit, up, sites)  # type: ignore[arg-type]
    try:
        skel = Skeleton(tuple(j.name for j in joints), parents, offsets, layout)
        nonroot = has_pos.copy()
        nonroot[0] = False
        return Motion(skel, fps, trans[:, 0], rot, trans if nonroot.any() else None, name=name)
    except MotionError as exc:
        raise BVHParseError(str(exc), file=fname) from None


def _axes_quat(a: F64) -> F64:
    from reactmocap.rotations import quat_from_matrix

    return quat_from_matrix(a)


def _span(parents: NDArray[np.int64], trans: F64, rot: F64) -> float:
    """Largest distance between any two joints over a few frames (file units)."""
    t, j = rot.shape[:2]
    g = np.empty_like(rot)
    p = np.empty((t, j, 3))
    g[:, 0] = rot[:, 0]
    p[:, 0] = trans[:, 0]
    for k in range(1, j):
        q = parents[k]
        g[:, k] = quat_mul(g[:, q], rot[:, k])
        p[:, k] = p[:, q] + quat_rotate(g[:, q], trans[:, k])
    d = np.linalg.norm(p[:, :, None] - p[:, None, :], axis=-1)
    return float(d.max())


def read_bvh(
    path: str | Path, *, unit: str | None = None, up: UpAxis = "y", name: str | None = None
) -> Motion:
    """Read a BVH file. Raises BVHParseError naming the file and line on any problem."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise BVHParseError(f"cannot read: {exc.strerror}", file=p, expected="a readable BVH file") from None
    if b"\x00" in raw[:4096]:
        raise BVHParseError("binary file", file=p, line=1, expected="a text BVH file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        try:
            text = raw.decode("latin-1")
        except UnicodeDecodeError:  # pragma: no cover - latin-1 decodes everything
            raise BVHParseError("not a text file", file=p, line=1, expected="UTF-8 text") from None
        if any(ord(c) < 9 for c in text[:4096]):
            raise BVHParseError("binary file", file=p, line=1, expected="a text BVH file")
    return parse_bvh(text, file=p, unit=unit, up=up, name=name or p.stem)


def bvh_text(
    motion: Motion, *, unit: str | None = None, up: UpAxis | None = None, precision: int = 6
) -> str:
    """BVH text of ``motion`` in its skeleton's source layout (or the given unit/up)."""
    skel = motion.skeleton
    lay = skel.layout
    unit = unit or lay.unit
    up = up or lay.up
    if unit not in UNIT_SCALE:
        raise MotionError(f"unit must be one of {list(UNIT_SCALE)}, got {unit!r}")
    inv = 1.0 / UNIT_SCALE[unit]
    a = axes_to_z_up(up)  # file -> internal; we need internal -> file = a.T
    qa = _axes_quat(a)
    qa_inv = qa * np.array([1, -1, -1, -1])
    rot_f = quat_mul(quat_mul(qa_inv, motion.rotations), qa)
    trans = np.array(motion.local_translations())
    trans[:, 0] = motion.root_positions
    trans_f = trans @ a * inv
    offsets_f = skel.offsets @ a * inv
    fmt = f"{{:.{precision}f}}"
    out = ["HIERARCHY"]
    children = {k: skel.children(k) for k in range(skel.num_joints)}

    def emit(k: int, depth: int) -> None:
        ind = "  " * depth
        kw = "ROOT" if k == 0 else "JOINT"
        out.append(f"{ind}{kw} {skel.names[k]}")
        out.append(f"{ind}{{")
        o = offsets_f[k]
        out.append(f"{ind}  OFFSET {' '.join(fmt.format(x) for x in o)}")
        ch = lay.channels[k]
        if ch:
            out.append(f"{ind}  CHANNELS {len(ch)} {' '.join(ch)}")
        for c in children[k]:
            emit(c, depth + 1)
        if k in lay.end_sites or not children[k]:
            e = np.array(lay.end_sites.get(k, (0.0, 0.0, 0.0))) @ a * inv
            out.append(f"{ind}  End Site")
            out.append(f"{ind}  {{")
            out.append(f"{ind}    OFFSET {' '.join(fmt.format(x) for x in e)}")
            out.append(f"{ind}  }}")
        out.append(f"{ind}}}")

    emit(0, 0)
    cols = []
    for k in range(skel.num_joints):
        ch = lay.channels[k]
        rot_ch = [c for c in ch if c in ROTATION_CHANNELS]
        eul = (
            np.degrees(quat_to_euler(rot_f[:, k], "".join(c[0] for c in rot_ch)))
            if rot_ch
            else None
        )
        r = 0
        for c in ch:
            if c in POSITION_CHANNELS:
                cols.append(trans_f[:, k, "XYZ".index(c[0])])
            else:
                assert eul is not None
                cols.append(eul[:, r])
                r += 1
    data = np.stack(cols, axis=1) if cols else np.zeros((motion.num_frames, 0))
    out.append("MOTION")
    out.append(f"Frames: {motion.num_frames}")
    out.append(f"Frame Time: {1.0 / motion.fps:.9f}")
    body = "\n".join(" ".join(fmt.format(x) for x in row) for row in data)
    return "\n".join(out) + "\n" + body + "\n"


def write_bvh(
    motion: Motion,
    path: str | Path,
    *,
    unit: str | None = None,
    up: UpAxis | None = None,
    precision: int = 6,
) -> None:
    """Write ``motion`` atomically (a temporary file renamed into place)."""
    atomic_write_text(path, bvh_text(motion, unit=unit, up=up, precision=precision))

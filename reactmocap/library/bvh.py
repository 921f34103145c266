"""BVH read/write with bulk numpy conversion of the frames.

Reading: a tokenizer pre-pass checks the HIERARCHY with line numbers (the ``bvh`` package keeps
none and mis-nests on stray braces), the ``bvh`` package builds the joint tree, a walk validates
it (a :class:`BVHParseError` names file, line and what was expected); ``np.loadtxt`` reads the
MOTION block.

Conventions: a file is Y-up unless ``up="z"``; its unit is detected from the body's span in the
first frames (:func:`reactmocap.conventions.detect_unit`) unless ``unit=`` is given. Channels
``Zrotation Xrotation Yrotation`` mean the intrinsic rotation ``Rz @ Rx @ Ry``. Position channels
on the root give its position; on other joints they replace the OFFSET (per-frame translations).
Internally everything is Z-up metres and wxyz quaternions; the Skeleton's :class:`BVHLayout`
keeps the source channels, unit and axes so that writing reproduces the source layout.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any, Literal

import numpy as np
from bvh import Bvh
from numpy.typing import NDArray

from reactmocap.conventions import UNIT_SCALE, Unit, UpAxis, axes_to_z_up, detect_unit
from reactmocap.errors import BVHParseError, ConfigError, MotionError
from reactmocap.io import atomic_write
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import (
    POSITION_CHANNELS,
    ROTATION_CHANNELS,
    VALID_CHANNELS,
    BVHLayout,
    Skeleton,
)
from reactmocap.rotations import (
    quat_conj,
    quat_from_euler,
    quat_from_matrix,
    quat_mul,
    quat_to_euler,
    quat_to_matrix,
)

__all__ = ["ChannelMode", "bvh_text", "parse_bvh", "read_bvh", "write_bvh"]

F64 = NDArray[np.float64]
ChannelMode = Literal["source", "rotation"]
Vec3 = tuple[float, float, float]
_Fail = Callable[..., BVHParseError]  # (message, line, expected) -> error to raise

_CHANNEL_NAMES = {c.lower(): c for c in VALID_CHANNELS}  # files vary in case: XROTATION, xrotation
_OPENERS = ("ROOT", "JOINT", "End")  # statements that must be followed by '{'
_KEYWORDS = (*_OPENERS, "OFFSET", "CHANNELS")
_BINARY = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")
_UNIT_FRAMES = 10  # frames used to detect the unit
#: largest magnitude of an OFFSET or channel value (file units or degrees): 1e7 cm is 100 km,
#: 1e7 degrees 28,000 turns; beyond it no motion is meant, and squared distances overflow
MAX_VALUE = 1e7
_RANGE = f"finite numbers within +-{MAX_VALUE:g}"


@dataclass
class _Joint:
    name: str
    parent: int
    offset: Vec3
    channels: tuple[str, ...]
    end_site: Vec3 | None
    line: int


# ---------------------------------------------------------------------------------- reading
def read_bvh(
    path: str | Path, *, unit: Unit | None = None, up: UpAxis = "y", name: str | None = None
) -> Motion:
    """Read a BVH file into a Motion (Z-up metres, wxyz). Any problem, a missing file included,
    raises :class:`BVHParseError` naming the file and, where there is one, the line."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise BVHParseError(
            f"cannot read: {exc.strerror or exc}", file=p, expected="a readable BVH file"
        ) from None
    return parse_bvh(_decode(raw, p), file=p, unit=unit, up=up, name=name or p.stem)


def _decode(raw: bytes, file: Path) -> str:
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        text = raw.decode("latin-1")  # old exporters write Latin-1 names; binary fails below
        if not _BINARY.search(text):
            return text
        line = raw.count(b"\n", 0, exc.start) + 1
        raise BVHParseError(
            f"not a text file (byte 0x{raw[exc.start]:02x} is not UTF-8)",
            file=file, line=line, expected="a UTF-8 text BVH file",
        ) from None  # fmt: skip
    return text


def parse_bvh(
    text: str,
    *,
    file: str | Path = "<string>",
    unit: Unit | None = None,
    up: UpAxis = "y",
    name: str | None = None,
) -> Motion:
    """Parse BVH text into a Motion; ``file`` only names the source in error messages."""
    fname = str(file)
    if up not in ("y", "z"):
        raise ConfigError(f"up must be 'y' or 'z', got {up!r}")
    if unit is not None and unit not in UNIT_SCALE:
        raise ConfigError(f"unit must be one of {list(UNIT_SCALE)}, got {unit!r}")
    if name is None:
        name = "" if fname == "<string>" else Path(fname).stem
    try:
        return _parse(text, fname, unit, up, name)
    except BVHParseError:
        raise
    except Exception as exc:
        # safety net (never hit by the fuzz tests): a located error is raised for every
        # problem we know of; anything else still reaches the caller as a BVHParseError
        raise BVHParseError(f"malformed BVH ({type(exc).__name__}: {exc})", file=fname) from exc


def _parse(text: str, fname: str, unit: Unit | None, up: UpAxis, name: str) -> Motion:
    def fail(msg: str, line: int | None, expected: str | None = None) -> BVHParseError:
        return BVHParseError(msg, file=fname, line=line, expected=expected)

    if (bad := _BINARY.search(text)) is not None:
        line = text.count("\n", 0, bad.start()) + 1
        raise fail(f"binary data (control character {bad.group()!r})", line, "a text BVH file")
    text = text.removeprefix("\ufeff")
    if "\r" in text:  # CRLF and old Mac files; split on "\n" only so line numbers match editors'
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    lines = text.split("\n")
    start = _next_content(lines, 0)
    if start is None:
        raise fail("empty file", 1, "HIERARCHY")
    if lines[start].split()[0] != "HIERARCHY":
        raise fail(f"found {lines[start].strip()[:40]!r}", start + 1, "HIERARCHY")
    motion_i = next((i for i in range(start + 1, len(lines)) if lines[i].strip() == "MOTION"), None)
    if motion_i is None:
        raise fail("no MOTION section", len(lines), "MOTION after the HIERARCHY")
    joints = _parse_hierarchy(lines, start, motion_i, fail)

    # MOTION header: "Frames: N" then "Frame Time: dt", each on its own line
    fr_i = _next_content(lines, motion_i + 1)
    if fr_i is None:
        raise fail("file ends after MOTION", len(lines), "Frames: <count>")
    m = re.fullmatch(r"Frames:\s*(\S+)", lines[fr_i].strip())
    if not m or not re.fullmatch(r"[+-]?\d+", m.group(1)):
        raise fail(f"found {lines[fr_i].strip()[:40]!r}", fr_i + 1, "Frames: <count>")
    n_frames = int(m.group(1))
    if n_frames <= 0:
        raise fail(f"Frames: {n_frames}", fr_i + 1, "at least one frame")
    ft_i = _next_content(lines, fr_i + 1)
    if ft_i is None:
        raise fail("file ends after Frames:", len(lines), "Frame Time: <seconds>")
    m = re.fullmatch(r"Frame\s+Time:\s*(\S+)", lines[ft_i].strip())
    try:
        ft_dec = Decimal(m.group(1)) if m else None
    except InvalidOperation:
        ft_dec = None
    if ft_dec is None:
        raise fail(f"found {lines[ft_i].strip()[:40]!r}", ft_i + 1, "Frame Time: <seconds>")
    if not (ft_dec.is_finite() and 0 < float(ft_dec) < float("inf")):
        raise fail(f"Frame Time: {ft_dec}", ft_i + 1, "a positive number of seconds")
    n_ch = sum(len(j.channels) for j in joints)
    if n_ch == 0:
        raise fail("no joint has CHANNELS", joints[0].line, "CHANNELS on at least one joint")
    data = _frames(lines[ft_i + 1 :], ft_i + 2, n_frames, n_ch, fail)
    return _to_motion(joints, data, _fps(ft_dec), unit, up, name, fail)


def _next_content(lines: Sequence[str], i: int) -> int | None:
    while i < len(lines):
        if lines[i].strip():
            return i
        i += 1
    return None


def _fps(frame_time: Decimal) -> float:
    """1 / Frame Time, snapped to a whole fps when the printed frame time is that rounded
    (``0.0333333`` -> 30, not 30.00003), so clips at the same rate concatenate and resample."""
    ft = float(frame_time)
    whole = round(1.0 / ft)
    half_ulp = 0.5 * 10.0 ** int(frame_time.as_tuple().exponent)
    if whole > 0 and abs(1.0 / whole - ft) <= half_ulp * (1 + 1e-9):
        return float(whole)
    return 1.0 / ft


def _parse_hierarchy(lines: list[str], start: int, stop: int, fail: _Fail) -> list[_Joint]:
    # Pre-pass: braces split onto their own lines (the bvh package only sees a brace at the start
    # of a line) with the source line of each statement, brace nesting checked where it breaks.
    norm: list[str] = []
    where: list[int] = []
    depth = 0
    pending: tuple[str, int] | None = None  # a ROOT/JOINT/End statement still waiting for '{'
    for i in range(start + 1, stop):
        stmt: list[str] = []
        for tok in [*lines[i].replace("{", " { ").replace("}", " } ").split(), None]:
            if tok not in ("{", "}", None):
                stmt.append(tok)
                continue
            if stmt:
                if pending:
                    raise fail(f"found {stmt[0]!r} after {pending[0]!r}", i + 1, "'{'")
                if stmt[0] not in _KEYWORDS:
                    raise fail(f"unknown keyword {stmt[0]!r}", i + 1,
                               "ROOT, JOINT, End Site, OFFSET, CHANNELS or a brace")  # fmt: skip
                norm.append(" ".join(stmt))
                where.append(i + 1)
                pending = (" ".join(stmt), i + 1) if stmt[0] in _OPENERS else None
                stmt = []
            if tok == "{":
                if not pending:
                    raise fail("'{' without a ROOT, JOINT or End Site before it", i + 1,
                               "'{' only after ROOT, JOINT or End Site")  # fmt: skip
                pending = None
                depth += 1
            elif tok == "}":
                if pending:
                    raise fail(f"found '}}' after {pending[0]!r}", i + 1, "'{'")
                if depth == 0:
                    raise fail("'}' without a matching '{'", i + 1, "MOTION")
                depth -= 1
            if tok is not None:
                norm.append(tok)
    if pending:
        raise fail(f"{pending[0]!r} has no '{{'", pending[1], "'{'")
    if depth:
        raise fail(f"{depth} unclosed '{{'", stop + 1, "'}' before MOTION")
    if not where:
        raise fail("empty HIERARCHY", start + 2, "ROOT")
    try:
        tree = Bvh("\n".join(norm) + "\n")
    except Exception as exc:  # the package raises bare IndexError/AttributeError on bad input
        raise fail(f"hierarchy not understood ({exc})", start + 1, "a BVH HIERARCHY") from None

    def preorder(node: Any) -> Iterator[Any]:
        for child in node.children:
            yield child
            yield from preorder(child)

    # the package appends nodes in document order, so pre-order pairs them with `where`
    line_of = {id(n): ln for n, ln in zip(preorder(tree.root), where, strict=True)}
    top = tree.root.children
    if top[0].value[0] != "ROOT":
        raise fail(f"found {top[0].value[0]!r}", line_of[id(top[0])], "ROOT")
    if len(top) > 1:
        raise fail(f"found {top[1].value[0]!r} after the ROOT joint (one skeleton per file)",
                   line_of[id(top[1])], "MOTION")  # fmt: skip
    joints: list[_Joint] = []
    _walk_joint(top[0], -1, joints, line_of, fail)
    return joints


def _walk_joint(
    node: Any, parent: int, out: list[_Joint], line_of: dict[int, int], fail: _Fail
) -> None:
    line = line_of[id(node)]
    kind = node.value[0]
    if len(node.value) < 2:
        raise fail(f"{kind} without a name", line, f"{kind} <name>")
    name = " ".join(node.value[1:])
    if any(j.name == name for j in out):
        raise fail(f"duplicate joint name {name!r}", line, "unique joint names")
    offset: Vec3 | None = None
    channels: tuple[str, ...] | None = None
    end_site: Vec3 | None = None
    kids = []
    for child in node.children:
        kw, cl = child.value[0], line_of[id(child)]
        if kw == "OFFSET" and offset is None:
            offset = _offset(child.value, cl, fail)
        elif kw == "CHANNELS" and channels is None:
            channels = _channels(child.value, cl, fail)
        elif kw == "JOINT":
            kids.append(child)
        elif kw == "End" and end_site is None:
            if child.value != ["End", "Site"]:
                raise fail(f"found {' '.join(child.value)!r}", cl, "End Site")
            sub = child.children
            if len(sub) != 1 or sub[0].value[0] != "OFFSET":
                raise fail(f"End Site of {name!r} needs exactly one OFFSET", cl, "OFFSET x y z")
            end_site = _offset(sub[0].value, line_of[id(sub[0])], fail)
        else:
            again = kw in ("OFFSET", "CHANNELS", "End")
            raise fail(f"{'second ' if again else ''}{kw!r} in joint {name!r}", cl,
                       "OFFSET, CHANNELS, JOINT or End Site, once each")  # fmt: skip
    if offset is None:
        raise fail(f"joint {name!r} has no OFFSET", line, "OFFSET x y z")
    out.append(_Joint(name, parent, offset, channels or (), end_site, line))
    idx = len(out) - 1
    for kid in kids:
        _walk_joint(kid, idx, out, line_of, fail)


def _offset(value: list[str], line: int, fail: _Fail) -> Vec3:
    if len(value) != 4:
        raise fail(f"OFFSET has {len(value) - 1} values", line, "OFFSET x y z")
    try:
        x, y, z = (float(v) for v in value[1:])
    except ValueError:
        raise fail(f"non-numeric OFFSET {' '.join(value[1:])!r}", line, "3 numbers") from None
    if not np.all(np.isfinite((x, y, z))):
        raise fail(f"OFFSET {' '.join(value[1:])}", line, "finite numbers")
    if max(abs(x), abs(y), abs(z)) > MAX_VALUE:
        raise fail(f"OFFSET {' '.join(value[1:])} out of range", line, _RANGE)
    return (x, y, z)


def _channels(value: list[str], line: int, fail: _Fail) -> tuple[str, ...]:
    if len(value) < 2 or not value[1].isdigit():
        raise fail(f"found {' '.join(value)!r}", line, "CHANNELS <count> <names>")
    names = value[2:]
    if len(names) != int(value[1]):
        raise fail(f"CHANNELS {value[1]} lists {len(names)} names", line, f"{value[1]} names")
    out = []
    for c in names:
        if c.lower() not in _CHANNEL_NAMES:
            raise fail(f"unknown channel name {c!r}", line, f"one of {', '.join(VALID_CHANNELS)}")
        out.append(_CHANNEL_NAMES[c.lower()])
    if len(set(out)) != len(out):
        raise fail(f"repeated channel in {' '.join(names)!r}", line, "each channel once")
    return tuple(out)


def _frames(body: list[str], first: int, n: int, n_ch: int, fail: _Fail) -> F64:
    """``(n, n_ch)`` frame values of the lines after Frame Time (``first`` = line of body[0])."""
    data: F64 | None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # loadtxt warns on empty input; checked below
            data = np.loadtxt(body, dtype=np.float64, comments=None, ndmin=2)
    except ValueError:
        data = None
    if data is None or data.shape != (n, n_ch):
        # slow path, only for bad files: find the first offending line
        rows = [(first + k, t) for k, s in enumerate(body) if (t := s.split())]
        if len(rows) < n:
            last_ok = rows and len(rows[-1][1]) == n_ch
            line = (rows[-1][0] + (1 if last_ok else 0)) if rows else first
            raise fail(f"truncated MOTION: {len(rows)} frame lines but Frames: {n}", line,
                       f"{n} frame lines")  # fmt: skip
        for r, (line, toks) in enumerate(rows[:n]):
            if len(toks) != n_ch:
                cut = r == n - 1 and len(toks) < n_ch and body[-1].strip() != ""  # no final \n
                what = "truncated MOTION: last frame line" if cut else "frame line"
                raise fail(f"{what} has {len(toks)} values", line,
                           f"{n_ch} values, one per channel")  # fmt: skip
            for tok in toks:
                try:
                    float(tok)
                except ValueError:
                    raise fail(f"non-numeric value {tok!r}", line, "a number") from None
        if len(rows) > n:
            raise fail(f"{len(rows) - n} frame lines beyond Frames: {n}", rows[n][0],
                       f"{n} frame lines")  # fmt: skip
        raise fail("unreadable frame data", first, f"{n} lines of {n_ch} numbers")
    sane = (np.abs(data) <= MAX_VALUE).all(axis=1)  # False for NaN too
    if not sane.all():
        row = int(np.flatnonzero(~sane)[0])
        line = first + [k for k, s in enumerate(body) if s.strip()][row]
        if not np.isfinite(data[row]).all():
            raise fail("NaN or infinite value in frame data", line, "finite numbers")
        big = data[row][np.argmax(np.abs(data[row]))]
        raise fail(f"value {big:g} out of range in frame data", line, _RANGE)
    return data


def _full_order(channels: Sequence[str]) -> str:
    """Euler order of a joint's rotation channels, padded with its missing axes (whose angle is 0)
    so that 0-2 rotation channels convert like 3; no rotation channels -> ZXY."""
    present = "".join(c[0] for c in channels if c in ROTATION_CHANNELS)
    return present + "".join(a for a in "XYZ" if a not in present) if present else "ZXY"


def _axes_quat(up: UpAxis) -> F64:
    return quat_from_matrix(axes_to_z_up(up))


def _to_motion(
    joints: list[_Joint],
    data: F64,
    fps: float,
    unit: Unit | None,
    up: UpAxis,
    name: str,
    fail: _Fail,
) -> Motion:
    t, nj = data.shape[0], len(joints)
    parents = np.array([j.parent for j in joints], dtype=np.int64)
    offsets_f = np.array([j.offset for j in joints], dtype=np.float64).reshape(nj, 3)
    trans_f = np.repeat(offsets_f[None], t, axis=0)
    euler = np.zeros((t, nj, 3))
    orders = [_full_order(j.channels) for j in joints]
    col = 0
    for k, j in enumerate(joints):  # J iterations: scatter columns, vectorised over frames
        for c in j.channels:
            if c in POSITION_CHANNELS:
                trans_f[:, k, "XYZ".index(c[0])] = data[:, col]
            else:
                euler[:, k, orders[k].index(c[0])] = data[:, col]
            col += 1
    rot_f = np.empty((t, nj, 4))
    for order in set(orders):
        ks = [k for k in range(nj) if orders[k] == order]
        rot_f[:, ks] = quat_from_euler(np.radians(euler[:, ks]), order)
    sites = {k: j.end_site for k, j in enumerate(joints) if j.end_site is not None}
    if unit is None:
        n = min(t, _UNIT_FRAMES)
        unit = detect_unit(_extent(parents, rot_f[:n], trans_f[:n], sites))
    scale = UNIT_SCALE[unit]
    a = axes_to_z_up(up)
    qa = _axes_quat(up)
    rot = quat_mul(quat_mul(qa, rot_f), quat_conj(qa))  # R_z = A R_file A^T
    trans = trans_f @ a.T * scale
    z_sites = {k: _vec(a @ np.asarray(o) * scale) for k, o in sites.items()}
    layout = BVHLayout(tuple(j.channels for j in joints), unit, up, z_sites)
    moving = any(any(c in POSITION_CHANNELS for c in j.channels) for j in joints[1:])
    try:
        skel = Skeleton(tuple(j.name for j in joints), parents, offsets_f @ a.T * scale, layout)
        return Motion(skel, fps, trans[:, 0], rot, trans if moving else None, name=name)
    except MotionError as exc:
        raise fail(str(exc), joints[0].line) from None


def _vec(x: Any) -> Vec3:
    return (float(x[0]), float(x[1]), float(x[2]))


def _extent(parents: NDArray[np.int64], rot: F64, trans: F64, sites: dict[int, Vec3]) -> float:
    """Largest distance between two points of the body (file units) over the given frames.

    The body is the subtree of the first joint with several children, so a dummy root left at the
    origin (as in the Bandai Namco files) does not count the actor's distance from the origin.
    """
    m = quat_to_matrix(rot)  # matrices: a few numpy calls per joint, not per frame
    g = np.empty_like(m)
    p = np.empty(trans.shape)
    g[:, 0], p[:, 0] = m[:, 0], trans[:, 0]
    nj = len(parents)
    for k in range(1, nj):
        q = parents[k]
        g[:, k] = g[:, q] @ m[:, k]
        p[:, k] = p[:, q] + (g[:, q] @ trans[:, k, :, None])[..., 0]
    b = 0
    while len(kids := np.flatnonzero(parents == b)) == 1:
        b = int(kids[0])
    body = np.zeros(nj, dtype=bool)
    body[b] = True
    for k in range(b + 1, nj):
        body[k] = body[parents[k]]
    pts = [p[:, body]] + [
        (p[:, k] + g[:, k] @ np.asarray(o))[:, None] for k, o in sites.items() if body[k]
    ]
    allp = np.concatenate(pts, axis=1)
    return float(np.linalg.norm(allp[:, :, None] - allp[:, None, :], axis=-1).max())


# ---------------------------------------------------------------------------------- writing
def write_bvh(
    motion: Motion,
    path: str | Path,
    *,
    unit: Unit | None = None,
    up: UpAxis | None = None,
    channels: ChannelMode = "source",
    precision: int = 6,
) -> None:
    """Write ``motion`` as BVH, atomically (a temporary sibling renamed into place, removed on
    any error). See :func:`bvh_text` for the options."""
    chunks = _bvh_chunks(motion, unit, up, channels, precision)
    first = next(chunks)  # bad arguments raise before any file is created
    with atomic_write(path, "w") as fh:
        fh.write(first)
        for chunk in chunks:
            fh.write(chunk)


def bvh_text(
    motion: Motion,
    *,
    unit: Unit | None = None,
    up: UpAxis | None = None,
    channels: ChannelMode = "source",
    precision: int = 6,
) -> str:
    """BVH text of ``motion``.

    ``unit``/``up`` default to the skeleton's source file's. ``channels="source"`` writes each
    joint's source channels; ``"rotation"`` writes 6 channels on the root and 3 rotation channels
    elsewhere; a joint gets the channels it lacks where the motion needs them (``"rotation"``
    ignores translations within 10 um of the offset), so writing never loses motion.
    ``precision`` is the number of decimals of every value.
    """
    return "".join(_bvh_chunks(motion, unit, up, channels, precision))


def _bvh_chunks(
    motion: Motion, unit: Unit | None, up: UpAxis | None, mode: str, precision: int
) -> Iterator[str]:
    skel, lay = motion.skeleton, motion.skeleton.layout
    unit = unit or lay.unit  # type: ignore[assignment]
    up = up or lay.up
    if unit not in UNIT_SCALE:
        raise MotionError(f"unit must be one of {list(UNIT_SCALE)}, got {unit!r}")
    if up not in ("y", "z"):
        raise MotionError(f"up must be 'y' or 'z', got {up!r}")
    if mode not in ("source", "rotation"):
        raise MotionError(f"channels must be 'source' or 'rotation', got {mode!r}")
    if not (isinstance(precision, int) and 0 <= precision <= 17):
        raise MotionError(f"precision must be an int in 0..17, got {precision!r}")
    t, nj = motion.num_frames, motion.num_joints
    inv = 1.0 / UNIT_SCALE[unit]
    a = axes_to_z_up(up)  # file -> Z-up; row vectors p_file = p_z @ a
    qa = _axes_quat(up)
    trans = np.array(motion.local_translations())
    trans[:, 0] = motion.root_positions
    trans_f = trans @ a * inv
    offsets_f = skel.offsets @ a * inv
    rot_f = quat_mul(quat_mul(quat_conj(qa), motion.rotations), qa)  # R_file = A^T R_z A
    tol = 0.5 * 10.0**-precision  # what the file cannot show anyway

    if mode == "rotation":
        chans = [POSITION_CHANNELS + _rot_names(lay.channels[0])] + [
            _rot_names(lay.channels[k]) for k in range(1, nj)
        ]
    else:
        chans = [tuple(c) for c in lay.channels]
    # values as [x, y, z, angle0, angle1, angle2] per joint in file axes / degrees, full order
    vals = np.empty((t, nj, 6))
    vals[..., :3] = trans_f
    orders = [_full_order(c) for c in chans]
    for order in set(orders):
        ks = [k for k in range(nj) if orders[k] == order]
        vals[:, ks, 3:] = np.degrees(quat_to_euler(rot_f[:, ks], order))
    # widen channels the data does not fit into; "rotation" ignores translation noise < 10 um
    pos_tol = tol if mode == "source" else max(tol, 1e-5 * inv)
    moved = np.abs(trans_f - offsets_f).max(axis=0) > pos_tol  # (J, 3) per file axis
    for k, ch in enumerate(chans):
        rot = rot0 = tuple(c for c in ch if c in ROTATION_CHANNELS)
        pos = pos0 = tuple(c for c in ch if c in POSITION_CHANNELS)
        if any(moved[k, i] and POSITION_CHANNELS[i] not in pos for i in range(3)):
            pos = POSITION_CHANNELS
        if len(rot) < 3 and np.abs(vals[:, k, 3 + len(rot) :]).max() > tol:
            rot = tuple(f"{x}rotation" for x in orders[k])
        if rot != rot0 or pos != pos0:
            chans[k] = pos + rot
    cols = [
        (k, "XYZ".index(c[0]) if c in POSITION_CHANNELS else 3 + orders[k].index(c[0]))
        for k in range(nj)
        for c in chans[k]
    ]
    data = vals[:, [k for k, _ in cols], [s for _, s in cols]] if cols else np.zeros((t, 0))

    fmt = f"{{:.{precision}f}}"

    def num(x: float) -> str:
        return fmt.format(round(float(x), precision) + 0.0)  # + 0.0: no "-0.000000"

    out = ["HIERARCHY"]
    children = [skel.children(k) for k in range(nj)]

    def emit(k: int, ind: str) -> None:
        out.append(f"{ind}{'ROOT' if k == 0 else 'JOINT'} {skel.names[k]}")
        out.append(f"{ind}{{")
        out.append(f"{ind}  OFFSET {' '.join(num(x) for x in offsets_f[k])}")
        if chans[k]:
            out.append(f"{ind}  CHANNELS {len(chans[k])} {' '.join(chans[k])}")
        for c in children[k]:
            emit(c, ind + "  ")
        if k in lay.end_sites or not children[k]:  # leaves get an End Site, as readers expect
            e = np.asarray(lay.end_sites.get(k, (0.0, 0.0, 0.0))) @ a * inv
            out.append(f"{ind}  End Site")
            out.append(f"{ind}  {{")
            out.append(f"{ind}    OFFSET {' '.join(num(x) for x in e)}")
            out.append(f"{ind}  }}")
        out.append(f"{ind}}}")

    emit(0, "")
    out += ["MOTION", f"Frames: {t}", f"Frame Time: {1.0 / motion.fps:.10g}", ""]
    yield "\n".join(out)
    data = np.round(data, precision) + 0.0
    row = " ".join([f"%.{precision}f"] * data.shape[1]) + "\n"
    for s in range(0, t, 1024):
        yield _format_rows(data[s : s + 1024], row)


def _rot_names(channels: Sequence[str]) -> tuple[str, ...]:
    return tuple(f"{x}rotation" for x in _full_order(channels))


def _format_rows(block: F64, row: str) -> str:
    return "".join(row % tuple(r) for r in block.tolist())

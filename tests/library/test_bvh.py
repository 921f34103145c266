"""BVH reader/writer: the real clips in ../shared/mocap, a generated CMU-style file with known
angles (proves the Euler and axis conventions), located errors for bad files, atomic writing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from reactmocap.errors import BVHParseError, MotionError
from reactmocap.library import bvh as bvh_mod
from reactmocap.library.bvh import bvh_text, parse_bvh, read_bvh, write_bvh
from reactmocap.library.motion import Motion
from reactmocap.library.skeleton import ROTATION_CHANNELS, BVHLayout, Skeleton
from reactmocap.rotations import quat_from_euler, quat_to_matrix

SHARED_MOCAP = Path(__file__).resolve().parents[2] / ".." / "shared" / "mocap"


# ------------------------------------------------------------------------------ helpers
def points(m: Motion) -> np.ndarray:
    """World positions of every joint and end site, (T, J + E, 3)."""
    return np.concatenate([m.global_positions(), m.end_site_positions()], axis=1)


def tallest(m: Motion) -> float:
    """Largest vertical extent of joints and end sites over the clip (m)."""
    z = points(m)[..., 2]
    return float((z.max(axis=1) - z.min(axis=1)).max())


def frame_values(text: str) -> np.ndarray:
    lines = text.split("\n")
    i = next(k for k, s in enumerate(lines) if s.startswith("Frame Time"))
    return np.loadtxt(lines[i + 1 :], ndmin=2)


def rot_x(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


# Y-up (x right, y up, z forward) to Z-up, written out here rather than imported
Y_TO_Z = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


# ------------------------------------------------------------------------- real clips
@pytest.fixture(scope="module")
def shared_clips() -> dict[Path, Motion]:
    d = SHARED_MOCAP.resolve()
    files = sorted(d.rglob("*.bvh")) if d.is_dir() else []
    if not files:
        pytest.skip(f"../shared/mocap not found: no .bvh files under {d} (present beside the repo)")
    return {f: read_bvh(f) for f in files}


def test_shared_clips_load(shared_clips: dict[Path, Motion]) -> None:
    for f, m in shared_clips.items():
        assert m.skeleton.layout.unit == "cm", f
        assert m.skeleton.layout.up == "y"
        assert m.fps == 30.0  # Frame Time 0.0333333 snaps to a whole rate
        assert m.name == f.stem
        assert m.num_frames == int(f.read_text().split("Frames:")[1].split()[0])
        # every joint has 6 channels, so per-frame translations are kept
        assert m.translations is not None
        assert m.skeleton.layout.end_sites


def test_shared_clips_height(shared_clips: dict[Path, Motion]) -> None:
    # The Bandai skeleton stops at the Head joint where the head end site is zero-length, and the
    # dash clip is crouched throughout (1.37 m at its tallest), so the per-clip bound is looser.
    heights = {f.name: tallest(m) for f, m in shared_clips.items()}
    assert all(1.3 <= h <= 2.0 for h in heights.values()), heights
    assert 1.4 <= float(np.median(list(heights.values()))) <= 2.0, heights


def test_shared_clips_round_trip(shared_clips: dict[Path, Motion], tmp_path: Path) -> None:
    for f, m in shared_clips.items():
        out = tmp_path / f.name
        write_bvh(m, out)
        back = read_bvh(out)
        tol = 1e-5 * tallest(m)
        assert back.num_frames == m.num_frames and back.fps == m.fps
        assert back.skeleton.names == m.skeleton.names
        assert back.skeleton.layout.channels == m.skeleton.layout.channels
        assert back.skeleton.layout.unit == "cm"
        assert np.abs(points(back) - points(m)).max() < tol, f
        # the numbers themselves come back (angles modulo 360)
        a, b = frame_values(f.read_text()), frame_values(out.read_text())
        rot = np.array([c in ROTATION_CHANNELS for ch in m.skeleton.layout.channels for c in ch])
        d = a - b
        d[:, rot] = (d[:, rot] + 180.0) % 360.0 - 180.0
        assert np.abs(d).max() < 1e-5, f


def test_shared_clip_rotation_channels(shared_clips: dict[Path, Motion], tmp_path: Path) -> None:
    m = next(iter(shared_clips.values()))
    write_bvh(m, tmp_path / "rot.bvh", channels="rotation")
    text = (tmp_path / "rot.bvh").read_text()
    # the dummy root and Hips (which carries the root motion) keep positions; the other joints'
    # position channels only repeat their offsets (to 1e-7 m) and are dropped
    assert text.count("CHANNELS 6") == 2
    assert text.count("CHANNELS 3 Zrotation Xrotation Yrotation") == m.num_joints - 2
    back = read_bvh(tmp_path / "rot.bvh")
    assert np.abs(points(back) - points(m)).max() < 1e-5 * tallest(m)


# ----------------------------------------------------- generated CMU-style file (inches)
CMU_JOINTS: list[tuple[str, str | None, tuple[float, float, float]]] = [("Hips", None, (0, 0, 0))]
for side, sx in (("Left", 1.0), ("Right", -1.0)):
    CMU_JOINTS += [
        (f"{side}UpLeg", "Hips", (3.5 * sx, 0, 0)),
        (f"{side}Leg", f"{side}UpLeg", (0, -17, 0)),
        (f"{side}Foot", f"{side}Leg", (0, -16.5, 0)),
        (f"{side}ToeBase", f"{side}Foot", (0, -1.5, 4.5)),
    ]
CMU_JOINTS += [
    ("Spine", "Hips", (0, 4, 0)),
    ("Spine1", "Spine", (0, 8, 0)),
    ("Neck", "Spine1", (0, 9, 0)),
    ("Head", "Neck", (0, 4, 0)),
]
for side, sx in (("Left", 1.0), ("Right", -1.0)):
    CMU_JOINTS += [
        (f"{side}Shoulder", "Spine1", (1.5 * sx, 7, 0)),
        (f"{side}Arm", f"{side}Shoulder", (5 * sx, 0, 0)),
        (f"{side}ForeArm", f"{side}Arm", (11 * sx, 0, 0)),
        (f"{side}Hand", f"{side}ForeArm", (10 * sx, 0, 0)),
    ]
CMU_ENDS = {"Head": (0, 7, 0), "LeftToeBase": (0, 0, 2), "RightToeBase": (0, 0, 2)}
CMU_ENDS |= {"LeftHand": (6, 0, 0), "RightHand": (-6, 0, 0)}
CMU_FRAMES = 24


def cmu_angles() -> tuple[np.ndarray, np.ndarray]:
    """Root positions (T, 3) inches and XYZ Euler angles (T, J, 3) degrees; frame 0 at rest."""
    rng = np.random.default_rng(7)
    j = len(CMU_JOINTS)
    ang = np.round(rng.uniform(-70, 70, size=(CMU_FRAMES, j, 3)), 4)
    ang[:, 0, 1] = np.round(rng.uniform(-179, 179, size=CMU_FRAMES), 4)  # root yaw
    ang[0] = 0.0
    pos = np.zeros((CMU_FRAMES, 3))
    pos[:, 0] = np.arange(CMU_FRAMES) * 0.5
    pos[:, 1] = 36.5
    return pos, ang


def cmu_bvh_text() -> str:
    pos, ang = cmu_angles()
    out = ["HIERARCHY"]

    def emit(k: int, ind: str) -> None:
        name, _, off = CMU_JOINTS[k]
        out.append(f"{ind}{'ROOT' if k == 0 else 'JOINT'} {name}")
        out.append(f"{ind}{{")
        out.append(f"{ind}\tOFFSET {off[0]:.4f} {off[1]:.4f} {off[2]:.4f}")
        rot = "Xrotation Yrotation Zrotation"
        chans = f"6 Xposition Yposition Zposition {rot}" if k == 0 else f"3 {rot}"
        out.append(f"{ind}\tCHANNELS {chans}")
        for c, (_, parent, _) in enumerate(CMU_JOINTS):
            if parent == name:
                emit(c, ind + "\t")
        if name in CMU_ENDS:
            e = CMU_ENDS[name]
            out.extend([f"{ind}\tEnd Site", f"{ind}\t{{", f"{ind}\t\tOFFSET {e[0]} {e[1]} {e[2]}"])
            out.append(f"{ind}\t}}")
        out.append(f"{ind}}}")

    emit(0, "")
    out += ["MOTION", f"Frames: {CMU_FRAMES}", "Frame Time: 0.00833333"]
    for t in range(CMU_FRAMES):
        out.append(" ".join(f"{v:.4f}" for v in [*pos[t], *ang[t].reshape(-1)]))
    return "\r\n".join(out) + "\r\n"  # CRLF, as Windows exporters write


@pytest.fixture
def cmu_file(tmp_path: Path) -> Path:
    p = tmp_path / "cmu_style.bvh"
    p.write_bytes(cmu_bvh_text().encode())
    return p


def test_cmu_style_file(cmu_file: Path, tmp_path: Path) -> None:
    m = read_bvh(cmu_file)
    assert m.fps == 120.0
    assert m.skeleton.layout.unit == "in"
    assert m.skeleton.names == tuple(n for n, _, _ in CMU_JOINTS)
    assert m.skeleton.layout.channels[1] == ("Xrotation", "Yrotation", "Zrotation")
    assert m.translations is None
    assert 1.5 <= m.slice(0, 1).height() <= 1.9  # frame 0 is the rest pose: 67 in
    write_bvh(m, tmp_path / "again.bvh")
    back = read_bvh(tmp_path / "again.bvh")
    assert back.fps == 120.0 and back.skeleton.layout.unit == "in"
    assert back.skeleton.layout.channels == m.skeleton.layout.channels
    assert np.abs(points(back) - points(m)).max() < 1e-5 * tallest(m)
    assert "Xrotation Yrotation Zrotation" in (tmp_path / "again.bvh").read_text()


def test_cmu_rotations_match_generating_angles(cmu_file: Path) -> None:
    """``Xrotation Yrotation Zrotation`` is R = Rx Ry Rz (intrinsic), taken to Z-up as A R A^T."""
    m = read_bvh(cmu_file)
    pos, ang = cmu_angles()
    got = quat_to_matrix(m.rotations)
    for t in range(CMU_FRAMES):
        for j in range(len(CMU_JOINTS)):
            r = rot_x(ang[t, j, 0]) @ rot_y(ang[t, j, 1]) @ rot_z(ang[t, j, 2])
            np.testing.assert_allclose(got[t, j], Y_TO_Z @ r @ Y_TO_Z.T, atol=1e-9)
    np.testing.assert_allclose(m.root_positions, pos @ Y_TO_Z.T * 0.0254, atol=1e-12)
    off = np.array([o for *_, o in CMU_JOINTS], dtype=float)
    np.testing.assert_allclose(m.skeleton.offsets, off @ Y_TO_Z.T * 0.0254, atol=1e-12)


def test_unit_override_and_metres(cmu_file: Path) -> None:
    m_in = read_bvh(cmu_file)
    m_cm = read_bvh(cmu_file, unit="cm")
    assert m_cm.skeleton.layout.unit == "cm"
    np.testing.assert_allclose(m_cm.skeleton.offsets * 2.54, m_in.skeleton.offsets)
    # the same body in metres is detected as metres
    back = parse_bvh(bvh_text(m_in, unit="m"))
    assert back.skeleton.layout.unit == "m"
    assert np.abs(points(back) - points(m_in)).max() < 1e-5
    back = parse_bvh(bvh_text(m_in, unit="mm", up="z"), up="z")
    assert back.skeleton.layout.unit == "mm"
    assert np.abs(points(back) - points(m_in)).max() < 1e-5


SMALL = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0 90 0 0 0 0 0 0 0
1 90 0 0 0 90 0 0 0
2 90 0 0 90 0 0 0 0
"""  # frame lines are 19-21


def test_y_up_becomes_z_up() -> None:
    m = parse_bvh(SMALL, unit="cm")
    np.testing.assert_allclose(m.skeleton.offsets[1], [0.0, 0.0, 0.1], atol=1e-15)
    np.testing.assert_allclose(m.skeleton.layout.end_sites[1], [0.0, 0.0, 0.1], atol=1e-15)
    np.testing.assert_allclose(m.root_positions[0], [0.0, 0.0, 0.9], atol=1e-15)
    pos = m.global_positions()
    np.testing.assert_allclose(pos[0, 1] - pos[0, 0], [0.0, 0.0, 0.1], atol=1e-15)
    # Yrotation 90 (yaw about the file's up axis) is a rotation about +Z
    s = np.sqrt(0.5)
    np.testing.assert_allclose(m.rotations[1, 0], [s, 0.0, 0.0, s], atol=1e-12)
    # Xrotation 90 tips the spine from up (+Y) to +Z in the file, which is -Y in Z-up
    np.testing.assert_allclose(pos[2, 1] - pos[2, 0], [0.0, -0.1, 0.0], atol=1e-12)
    z = parse_bvh(SMALL, unit="cm", up="z")
    np.testing.assert_allclose(z.skeleton.offsets[1], [0.0, 0.1, 0.0])


def test_fps_and_names() -> None:
    m = parse_bvh(SMALL, unit="cm")
    assert m.fps == 30.0 and m.name == ""
    odd = parse_bvh(SMALL.replace("0.0333333", "0.0333667"), unit="cm")
    assert odd.fps == pytest.approx(1 / 0.0333667)
    back = parse_bvh(bvh_text(odd))
    assert back.fps == pytest.approx(odd.fps, rel=1e-9)
    assert parse_bvh(SMALL, name="x").name == "x"


def test_output_syntax_is_plain_bvh() -> None:
    from bvh import Bvh  # an independent reader agrees on the structure

    m = parse_bvh(SMALL, unit="cm")
    text = bvh_text(m)
    assert text.startswith("HIERARCHY\nROOT Hips\n{\n  OFFSET ")
    ft = next(s for s in text.split("\n") if s.startswith("Frame Time:"))
    assert len(ft.split()[-1].split(".")[1]) >= 7
    ref = Bvh(text)
    assert ref.get_joints_names() == ["Hips", "Spine"]
    assert ref.nframes == 3 and len(ref.frames) == 3
    assert all(len(f) == 9 for f in ref.frames)
    assert "-0.000000" not in text


def test_channel_variety_round_trips() -> None:
    """0 rotation channels, partial position channels and non-root positions all come back."""
    text = SMALL.replace(
        "CHANNELS 3 Zrotation Xrotation Yrotation",
        "CHANNELS 4 Yposition Yrotation Xrotation Zrotation",
    ).replace("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
              "CHANNELS 5 Xposition Zposition Zrotation Xrotation Yrotation")  # fmt: skip
    lines = text.split("\n")
    lines[18:21] = ["0 0 0 0 0 10 0 0 0", "1 0 0 0 90 11 0 0 0", "2 0 90 0 0 12 0 0 0"]
    m = parse_bvh("\n".join(lines), unit="cm")
    assert m.skeleton.layout.channels[1] == ("Yposition", "Yrotation", "Xrotation", "Zrotation")
    assert m.translations is not None
    np.testing.assert_allclose(m.translations[:, 1, 2], [0.10, 0.11, 0.12])
    np.testing.assert_allclose(m.root_positions[:, 2], 0.0)  # root Y comes from its OFFSET
    back = parse_bvh(bvh_text(m), unit="cm")
    assert back.skeleton.layout.channels == m.skeleton.layout.channels
    np.testing.assert_allclose(points(back), points(m), atol=1e-8)
    # a joint without rotation channels is identity; a channel-less joint is allowed
    bare = SMALL.replace("    CHANNELS 3 Zrotation Xrotation Yrotation\n", "")
    rows = bare.split("\n")
    rows[17:20] = [r.rsplit(" 0 0 0", 1)[0] for r in rows[17:20]]  # drop the spine's values
    bare = "\n".join(rows)
    b = parse_bvh(bare, unit="cm")
    assert b.skeleton.layout.channels[1] == ()
    np.testing.assert_allclose(b.rotations[:, 1], [[1, 0, 0, 0]] * 3)


def test_source_channels_widen_when_needed() -> None:
    """A root without position channels that moves, or a joint given a rotation it had no
    channels for, gets the channels it needs instead of losing the data."""
    m = parse_bvh(SMALL, unit="cm")
    lay = m.skeleton.layout
    skel = Skeleton(
        m.skeleton.names,
        m.skeleton.parents,
        m.skeleton.offsets,
        BVHLayout((("Zrotation", "Xrotation", "Yrotation"), ()), lay.unit, lay.up, lay.end_sites),
    )
    rot = np.array(m.rotations)
    rot[:, 1] = quat_from_euler([0.3, 0.2, 0.1], "ZXY")
    moved = Motion(skel, m.fps, m.root_positions, rot)
    back = parse_bvh(bvh_text(moved), unit="cm")
    assert back.skeleton.layout.channels[0][:3] == ("Xposition", "Yposition", "Zposition")
    assert back.skeleton.layout.channels[1] == ("Zrotation", "Xrotation", "Yrotation")
    np.testing.assert_allclose(points(back), points(moved), atol=1e-8)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    order=st.permutations("XYZ"),
    angles=st.lists(st.floats(-180.0, 180.0), min_size=18, max_size=18),
    up=st.sampled_from(["y", "z"]),
    unit=st.sampled_from(["m", "cm", "mm", "in"]),
)
def test_random_euler_round_trip(order: list[str], angles: list[float], up: str, unit: str) -> None:
    o = "".join(order)
    rot = [f"{a}rotation" for a in o]
    layout = BVHLayout(
        (("Xposition", "Yposition", "Zposition", *rot), tuple(rot), tuple(rot)),
        unit,
        up,  # type: ignore[arg-type]
        {2: (0.0, 0.0, 0.1)},
    )
    offsets = np.array([[0, 0, 0], [0, 0, 0.3], [0.2, 0, 0]])
    skel = Skeleton(("a", "b", "c"), np.array([-1, 0, 1]), offsets, layout)
    q = quat_from_euler(np.radians(np.reshape(angles, (2, 3, 3))), o)
    m = Motion(skel, 60.0, np.array([[0.1, 0.2, 0.9], [0.0, 0.0, 1.0]]), q)
    back = parse_bvh(bvh_text(m), unit=unit, up=up)  # type: ignore[arg-type]
    assert back.skeleton.layout.channels == layout.channels
    dots = np.abs(np.sum(back.rotations * m.rotations, axis=-1))
    assert np.all(dots > 1 - 1e-10)
    assert np.abs(points(back) - points(m)).max() < 1e-5


# ------------------------------------------------------------------------ bad input
def bad(text: str | bytes, tmp_path: Path, **kw: object) -> BVHParseError:
    p = tmp_path / "bad.bvh"
    p.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(BVHParseError) as info:
        read_bvh(p, unit="cm", **kw)  # type: ignore[arg-type]
    err = info.value
    assert err.file == str(p)
    return err


def lines_of(text: str) -> list[str]:
    return text.split("\n")


def join(lines: list[str]) -> str:
    return "\n".join(lines)


def test_small_is_valid() -> None:
    assert parse_bvh(SMALL, unit="cm").num_frames == 3


def test_truncated_motion(tmp_path: Path) -> None:
    e = bad(join(lines_of(SMALL)[:20]), tmp_path)
    assert e.line == 21 and "truncated" in e.reason and e.expected == "3 frame lines"
    # cut inside the last line: that line is the culprit
    e = bad(SMALL[: SMALL.rindex(" 0 0 0")], tmp_path)
    assert e.line == 21 and "truncated" in e.reason and "9 values" in (e.expected or "")


def test_wrong_value_count(tmp_path: Path) -> None:
    lines = lines_of(SMALL)
    lines[19] += " 7"
    e = bad(join(lines), tmp_path)
    assert e.line == 20 and "10 values" in e.reason and "9 values" in (e.expected or "")
    lines = lines_of(SMALL)
    lines[18] = "0 90 0"
    e = bad(join(lines), tmp_path)
    assert e.line == 19 and "9 values" in (e.expected or "")


def test_non_numeric_token(tmp_path: Path) -> None:
    lines = lines_of(SMALL)
    lines[19] = lines[19].replace("90", "9O", 1)
    e = bad(join(lines), tmp_path)
    assert e.line == 20 and "'9O'" in e.reason and e.expected == "a number"


@pytest.mark.parametrize("value", ["nan", "NaN", "inf", "-inf", "1e999"])
def test_nan_or_inf(tmp_path: Path, value: str) -> None:
    lines = lines_of(SMALL)
    lines[20] = lines[20].replace("90", value, 1)
    e = bad(join(lines), tmp_path)
    assert e.line == 21 and e.expected == "finite numbers"
    lines = lines_of(SMALL)
    lines[7] = f"    OFFSET 0 {value} 0"
    e = bad(join(lines), tmp_path)
    assert e.line == 8 and e.expected == "finite numbers"


@pytest.mark.parametrize("value", ["1e300", "-2e7"])
def test_values_out_of_range(tmp_path: Path, value: str) -> None:
    # finite but absurd (100 km, 28,000 turns and more): refused at its line, not left to
    # overflow later (1e300 cm made `search build` fail with numpy's "must not contain infs")
    lines = lines_of(SMALL)
    lines[20] = lines[20].replace("90", value, 1)
    e = bad(join(lines), tmp_path)
    assert e.line == 21 and e.expected == "finite numbers within +-1e+07"
    assert f"value {float(value):g} out of range" in e.reason
    lines = lines_of(SMALL)
    lines[7] = f"    OFFSET 0 {value} 0"
    e = bad(join(lines), tmp_path)
    assert e.line == 8 and "out of range" in e.reason


def test_missing_hierarchy(tmp_path: Path) -> None:
    e = bad(join(lines_of(SMALL)[1:]), tmp_path)
    assert e.line == 1 and e.expected == "HIERARCHY"


def test_missing_motion(tmp_path: Path) -> None:
    e = bad(join(lines_of(SMALL)[:15]), tmp_path)
    assert e.expected is not None and "MOTION" in e.expected
    e = bad(join(lines_of(SMALL)[:16]), tmp_path)  # MOTION but no header
    assert e.expected == "Frames: <count>"


def test_unknown_channel(tmp_path: Path) -> None:
    e = bad(SMALL.replace("3 Zrotation", "3 Qrotation"), tmp_path)
    assert e.line == 9 and "'Qrotation'" in e.reason and "Xrotation" in (e.expected or "")


def test_channel_count_mismatch(tmp_path: Path) -> None:
    e = bad(SMALL.replace("CHANNELS 3", "CHANNELS 4"), tmp_path)
    assert e.line == 9 and e.expected == "4 names"


def test_lowercase_channels_are_accepted() -> None:
    spine = "Zrotation Xrotation Yrotation\n    End"
    m = parse_bvh(SMALL.replace(spine, "zrotation XROTATION yrotation\n    End"), unit="cm")
    assert m.skeleton.layout.channels[1] == ("Zrotation", "Xrotation", "Yrotation")


def test_zero_frames(tmp_path: Path) -> None:
    e = bad(join([*lines_of(SMALL)[:16], "Frames: 0", "Frame Time: 0.0333333", ""]), tmp_path)
    assert e.line == 17 and e.expected == "at least one frame"


@pytest.mark.parametrize("ft", ["0", "-0.01", "0.0", "nan", "inf", "abc"])
def test_bad_frame_time(tmp_path: Path, ft: str) -> None:
    e = bad(SMALL.replace("Frame Time: 0.0333333", f"Frame Time: {ft}"), tmp_path)
    assert e.line == 18
    assert e.expected in ("a positive number of seconds", "Frame Time: <seconds>")


def test_duplicate_joint_names(tmp_path: Path) -> None:
    e = bad(SMALL.replace("JOINT Spine", "JOINT Hips"), tmp_path)
    assert e.line == 6 and "'Hips'" in e.reason and e.expected == "unique joint names"


@pytest.mark.parametrize("text", ["", "   \n\n\t\n"])
def test_empty_file(tmp_path: Path, text: str) -> None:
    e = bad(text, tmp_path)
    assert e.line == 1 and "empty" in e.reason and e.expected == "HIERARCHY"


def test_binary_files(tmp_path: Path) -> None:
    e = bad(np.random.default_rng(0).bytes(4000), tmp_path)
    assert e.expected is not None and "text" in e.expected
    e = bad(b"\x00" * 100, tmp_path)
    assert e.line == 1 and "binary" in e.reason
    e = bad(SMALL.encode().replace(b"OFFSET 0 10 0", b"OFFSET 0 10\x00 0", 1), tmp_path)
    assert e.line == 8 and "binary" in e.reason
    e = bad(SMALL.encode().replace(b"Spine", b"Spine\xff\xfe\x01", 1), tmp_path)
    assert e.line == 6 and "UTF-8" in e.reason


def test_latin1_names_are_read(tmp_path: Path) -> None:
    p = tmp_path / "latin1.bvh"
    p.write_bytes(SMALL.replace("Spine", "Rücken").encode("latin-1"))
    assert read_bvh(p, unit="cm").skeleton.names == ("Hips", "Rücken")


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(BVHParseError) as info:
        read_bvh(tmp_path / "nope.bvh")
    assert info.value.file == str(tmp_path / "nope.bvh") and "cannot read" in info.value.reason


@pytest.mark.parametrize(
    ("edit", "line", "expected"),
    [
        (lambda ls: ls[:6] + ls[7:], 7, "'{'"),  # JOINT without '{'
        (lambda ls: ls[:13] + ls[14:], 15, "'}' before MOTION"),  # unclosed brace
        (lambda ls: [*ls[:14], "}", *ls[14:]], 16, "MOTION"),  # stray '}'
        (lambda ls: ls[:7] + ls[8:], 6, "OFFSET x y z"),  # joint without OFFSET
        (lambda ls: [*ls[:7], "    OFFSET 0 10", *ls[8:]], 8, "OFFSET x y z"),
        (lambda ls: [*ls[:7], "    OFFSET 0 ten 0", *ls[8:]], 8, "3 numbers"),
        (lambda ls: [*ls[:7], "    OFSET 0 10 0", *ls[8:]], 8, None),  # unknown keyword
        (lambda ls: [*ls[:15], "ROOT Other", "{", "OFFSET 0 0 0", "}", *ls[15:]], 16, "MOTION"),
        (lambda ls: [*ls[:21], "3 90 0 0 0 0 0 0 0", ""], 22, "3 frame lines"),  # extra frame
        (lambda ls: ["HIERARCHY", "JOINT Hips", *ls[2:]], 2, "ROOT"),
        (lambda ls: [*ls[:16], "Frames: three", *ls[17:]], 17, "Frames: <count>"),
        (lambda ls: [*ls[:16], "Frame Time: 0.03", "Frames: 3", *ls[18:]], 17, "Frames: <count>"),
    ],
)
def test_structural_errors(tmp_path: Path, edit: object, line: int, expected: str | None) -> None:
    e = bad(join(edit(lines_of(SMALL))), tmp_path)  # type: ignore[operator]
    assert e.line == line
    if expected is not None:
        assert e.expected == expected
    else:
        assert e.expected
    assert f"bad.bvh:{line}:" in str(e)


@settings(max_examples=300, deadline=None)
@given(cut=st.integers(0, len(SMALL)), junk=st.text(max_size=6), pos=st.integers(0, len(SMALL)))
def test_mangled_files_raise_only_bvh_errors(cut: int, junk: str, pos: int) -> None:
    for text in (SMALL[:cut], SMALL[:pos] + junk + SMALL[pos:], SMALL[:pos] + SMALL[pos + 3 :]):
        try:
            parse_bvh(text, unit="cm")
        except BVHParseError as exc:
            assert exc.reason
            assert exc.line is None or 1 <= exc.line <= text.count("\n") + 2


# ---------------------------------------------------------------------- atomic writing
def test_write_failure_leaves_no_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    m = parse_bvh(SMALL, unit="cm")
    target = tmp_path / "out.bvh"

    def boom(*args: object) -> str:
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(bvh_mod, "_format_rows", boom)  # fails after the header is written
    with pytest.raises(RuntimeError):
        write_bvh(m, target)
    assert list(tmp_path.iterdir()) == []
    target.write_text("old contents")
    with pytest.raises(RuntimeError):
        write_bvh(m, target)
    assert target.read_text() == "old contents"
    assert list(tmp_path.iterdir()) == [target]


def test_write_bad_arguments_create_nothing(tmp_path: Path) -> None:
    m = parse_bvh(SMALL, unit="cm")
    for kw in ({"unit": "furlong"}, {"up": "x"}, {"channels": "all"}, {"precision": -1}):
        with pytest.raises(MotionError):
            write_bvh(m, tmp_path / "x.bvh", **kw)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []


def test_write_then_read_file(tmp_path: Path) -> None:
    m = parse_bvh(SMALL, unit="cm")
    write_bvh(m, tmp_path / "sub" / "out.bvh", precision=8)
    back = read_bvh(tmp_path / "sub" / "out.bvh", unit="cm")  # a 20 cm toy: no detection
    assert back.name == "out"
    np.testing.assert_allclose(points(back), points(m), atol=1e-10)

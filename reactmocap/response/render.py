"""Video of a response rendered with MuJoCo's offscreen renderer: the characters as their
simulation bodies (capsules and foot boxes), plus an optional translucent "ghost" of the found
clip, on a floor, from a camera that follows the recipient.

Headless machines need an offscreen GL: set ``MUJOCO_GL=egl`` (or ``osmesa``) before MuJoCo
is imported; the ``reactmocap`` command does this itself when there is no display. Where no GL
context can be made, :func:`render_video` raises :class:`RenderUnavailable` and the caller
falls back to the matplotlib stick figure.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import mujoco
import numpy as np

from reactmocap.errors import ReactMocapError
from reactmocap.library.motion import Motion
from reactmocap.response.plots import imageio_v3, write_video
from reactmocap.sim.character import build_character

__all__ = ["RenderUnavailable", "free_camera", "offscreen_renderer", "render_video"]

RGBA = tuple[float, float, float, float]


class RenderUnavailable(ReactMocapError):
    """No OpenGL context for MuJoCo's offscreen renderer on this machine."""


def offscreen_renderer(model: mujoco.MjModel, size: tuple[int, int]) -> mujoco.Renderer:
    """MuJoCo's offscreen renderer for ``model`` at ``size`` (width, height); raises
    RenderUnavailable where no GL context can be made."""
    width, height = size
    try:
        return mujoco.Renderer(model, height=height, width=width)
    except Exception as exc:  # each GL backend fails in its own way
        raise RenderUnavailable(
            f"MuJoCo offscreen rendering unavailable (MUJOCO_GL="
            f"{os.environ.get('MUJOCO_GL', 'unset')!r}): {exc}"
        ) from exc


def free_camera(distance: float, elevation: float, azimuth: float) -> mujoco.MjvCamera:
    """A free camera ``distance`` (m) from its look-at point, ``elevation`` and ``azimuth``
    (deg); the caller moves its ``lookat``."""
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.distance, cam.elevation, cam.azimuth = distance, elevation, azimuth
    return cam


def _scene(chars: Sequence[mujoco.MjSpec]) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    spec.worldbody.add_light(
        pos=[0.0, 0.0, 6.0], dir=[0.0, 0.0, -1.0], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    )
    # a sky and a checkered floor to the horizon: no black bands around the scene
    spec.add_texture(name="sky", type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
                     builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT, rgb1=[0.75, 0.85, 0.95],
                     rgb2=[0.97, 0.97, 0.98], width=256, height=256)  # fmt: skip
    spec.add_texture(name="grid", type=mujoco.mjtTexture.mjTEXTURE_2D,
                     builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER, rgb1=[0.80, 0.82, 0.84],
                     rgb2=[0.72, 0.74, 0.77], width=256, height=256)  # fmt: skip
    mat = spec.add_material(name="grid", texrepeat=[1.0, 1.0], texuniform=True)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "grid"
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 0.05],
                            material="grid")  # fmt: skip
    for k, ch in enumerate(chars):
        spec.attach(ch, prefix=f"c{k}/", frame=spec.worldbody.add_frame())
    model = spec.compile()
    model.vis.headlight.ambient[:] = 0.35
    model.vis.headlight.diffuse[:] = 0.6
    model.vis.rgba.haze[:] = (0.9, 0.92, 0.95, 1.0)
    return model


def render_video(
    motions: Sequence[tuple[Motion, RGBA]],
    path: str | Path,
    *,
    fps: float = 30.0,
    size: tuple[int, int] = (512, 384),
    ghost: tuple[Motion, RGBA] | None = None,
    hit: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> Path:
    """Render ``motions`` (each with a colour; the first is followed by the camera) and an
    optional ``ghost`` into an MP4 (or GIF, by ``path``'s suffix), written atomically. ``hit``
    (times, points, forces on the recipient) draws the contact point and its force as an arrow
    while the hit lasts (1 kN: 0.25 m).

    Raises RenderUnavailable if no GL context can be created, ReactMocapError if the video
    writer (imageio, the ``video`` extra) is missing.
    """
    imageio_v3()  # fail before rendering if the writer is missing
    items = list(motions) + ([ghost] if ghost is not None else [])
    if not items:
        raise ReactMocapError("render_video needs at least one motion")
    chars = [build_character(m, frame=0) for m, _ in items]
    model = _scene([c.make_spec() for c in chars])
    data = mujoco.MjData(model)
    n = max(int(round(m.duration * fps)) + 1 for m, _ in items)
    times = np.arange(n) / fps
    qadr = [int(model.jnt_qposadr[model.joint(f"c{k}/root").id]) for k in range(len(items))]
    qpos = []
    for k, (m, rgba) in enumerate(items):
        qpos.append(chars[k].qpos_from_motion(m.sample(np.minimum(times, m.duration))))
        bodies = [b for b in range(model.nbody) if model.body(b).name.startswith(f"c{k}/")]
        model.geom_rgba[np.isin(model.geom_bodyid, bodies)] = rgba
    width, height = size
    renderer = offscreen_renderer(model, size)
    cam = free_camera(4.0, -15.0, 135.0)
    pelvis = qpos[0][:, :3]
    # follow the recipient smoothly: the lookat is a 0.5 s moving average of its pelvis
    k = max(1, int(fps * 0.5))
    kernel = np.ones(k) / k
    look = np.stack(
        [np.convolve(np.pad(pelvis[:, i], (k // 2, k - 1 - k // 2), mode="edge"), kernel, "valid")
         for i in range(3)], axis=1,
    )  # fmt: skip
    frames = np.empty((n, height, width, 3), dtype=np.uint8)
    try:
        for i in range(n):
            for a, q in zip(qadr, qpos, strict=True):
                data.qpos[a : a + q.shape[1]] = q[min(i, len(q) - 1)]
            mujoco.mj_kinematics(model, data)
            cam.lookat[:] = (look[i, 0], look[i, 1], 0.9)
            renderer.update_scene(data, camera=cam)
            if hit is not None:
                _mark_hit(renderer.scene, hit, times[i], 0.5 / fps)
            frames[i] = renderer.render()
    finally:
        renderer.close()
    return write_video(frames, path, fps)


def _mark_hit(
    scene: mujoco.MjvScene, hit: tuple[np.ndarray, np.ndarray, np.ndarray], t: float, tol: float
) -> None:
    """The contact point (a yellow sphere) and the force on the recipient (an arrow into it) at
    time ``t``, if the hit lasts then."""
    times, points, forces = hit
    near = np.flatnonzero(np.abs(times - t) <= tol)
    if near.size == 0 or scene.ngeom + 2 > scene.maxgeom:
        return
    k = near[np.argmax(np.linalg.norm(forces[near], axis=1))]
    p, f = points[k], forces[k]
    red = np.array([1.0, 0.85, 0.0, 1.0])  # yellow: visible on both characters
    g = scene.geoms[scene.ngeom]
    mujoco.mjv_initGeom(g, mujoco.mjtGeom.mjGEOM_SPHERE, np.array([0.03, 0, 0]), p,
                        np.eye(3).ravel(), red)  # fmt: skip
    scene.ngeom += 1
    n = float(np.linalg.norm(f))
    if n > 1e-6:
        tail = p - f / n * max(0.08, 0.25 * n / 1000.0)  # the arrow ends at the point
        g = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(g, mujoco.mjtGeom.mjGEOM_ARROW, np.zeros(3), np.zeros(3),
                            np.eye(3).ravel(), red)  # fmt: skip
        mujoco.mjv_connector(g, mujoco.mjtGeom.mjGEOM_ARROW, 0.015, tail, p)
        scene.ngeom += 1

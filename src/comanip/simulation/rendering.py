"""Pictures of a simulated trial: an offscreen frame strip, and a replay in MuJoCo's viewer when a display exists.

Offscreen rendering needs an OpenGL backend chosen *before* MuJoCo is imported: on a machine without a
display, call :func:`choose_headless_backend` first (it selects EGL, or OSMesa, when their libraries are
installed). Without a working backend the strip is skipped with the reason, never an error.
"""

from __future__ import annotations

import ctypes.util
import os
from pathlib import Path

import numpy as np


def has_display() -> bool:
    """True when an X or Wayland display is available for a window."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def choose_headless_backend() -> str | None:
    """Set MUJOCO_GL for offscreen rendering when there is no display and it is unset; returns the backend
    in effect ('egl', 'osmesa', the user's choice, or None when none is available). Call before importing mujoco."""
    if "MUJOCO_GL" in os.environ or has_display():
        return os.environ.get("MUJOCO_GL")
    for backend, library in (("egl", "EGL"), ("osmesa", "OSMesa")):
        if ctypes.util.find_library(library):
            os.environ["MUJOCO_GL"] = backend
            return backend
    return None


def render_frame_strip(model, qpos: np.ndarray, path: str | Path, markers=(), frames: int = 6,
                       size: tuple[int, int] = (240, 320)) -> tuple[Path | None, str]:
    """Render `frames` evenly spaced postures of qpos (K, nq) side by side into a PNG, with green spheres
    at the marker positions (each (3,), m; e.g. the goal).

    Returns (path, "") on success or (None, reason) when offscreen rendering is not available here.
    """
    import matplotlib.pyplot as plt
    import mujoco

    try:
        renderer = mujoco.Renderer(model, *size)
    except Exception as error:  # no GL context: the backend's libraries or a display are missing
        return None, f"offscreen rendering unavailable ({type(error).__name__}: {error})"
    data = mujoco.MjData(model)
    camera = mujoco.MjvCamera()
    camera.lookat[:] = [0.4, 0.15, 0.3]
    camera.distance, camera.azimuth, camera.elevation = 1.4, 140.0, -20.0
    images = []
    with renderer:
        for k in np.linspace(0, len(qpos) - 1, frames).astype(int):
            data.qpos[:] = qpos[k]
            mujoco.mj_forward(model, data)
            renderer.update_scene(data, camera)
            for position in markers:
                _add_sphere(renderer.scene, position, 0.02, (0.1, 0.8, 0.2, 0.8))
            images.append(renderer.render().copy())
    plt.imsave(path, np.concatenate(images, axis=1))
    return Path(path), ""


def replay_in_viewer(model, t: np.ndarray, qpos: np.ndarray) -> str:
    """Replay postures qpos (K, nq) at times t (K,) s in MuJoCo's passive viewer, in real time; returns a
    message (why nothing was shown, when no display exists)."""
    if not has_display():
        return "no display: viewer skipped"
    import time

    import mujoco
    import mujoco.viewer

    data = mujoco.MjData(model)
    with mujoco.viewer.launch_passive(model, data) as viewer:
        begin = time.perf_counter()
        for k in range(len(t)):
            if not viewer.is_running():
                break
            data.qpos[:] = qpos[k]
            mujoco.mj_forward(model, data)
            viewer.sync()
            time.sleep(max(0.0, t[k] - (time.perf_counter() - begin)))
    return "replayed in the viewer"


def _add_sphere(scene, position, radius: float, rgba) -> None:
    """Append a sphere (radius m at position (3,) m) to an mjvScene for this frame only."""
    import mujoco

    if scene.ngeom >= scene.maxgeom:
        return
    mujoco.mjv_initGeom(scene.geoms[scene.ngeom], mujoco.mjtGeom.mjGEOM_SPHERE, np.full(3, radius),
                        np.asarray(position, dtype=float), np.eye(3).ravel(), np.asarray(rgba, dtype=np.float32))
    scene.ngeom += 1

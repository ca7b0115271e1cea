"""Pictures of a simulated trial: an offscreen frame strip, and a replay in MuJoCo's viewer when a display exists.

Offscreen rendering needs an OpenGL backend chosen *before* MuJoCo is imported (MUJOCO_GL), and a missing
one can abort the process rather than raise. So the strip is drawn in a child process with the backend set
(:func:`headless_backend`: EGL, else OSMesa, when their libraries exist); when that fails the strip is
skipped with the reason, and the simulation's results are unaffected.

    python -m comanip.simulation.rendering frames.npz strip.png    # what the child runs
"""

from __future__ import annotations

from typing import NamedTuple

import ctypes.util
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np


def has_display() -> bool:
    """True when an X or Wayland display is available for a window."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def headless_backend() -> str | None:
    """The MUJOCO_GL value for offscreen rendering here: the user's, else 'egl' or 'osmesa' when their
    library is installed, else 'glfw' with a display; None when nothing can render."""
    if "MUJOCO_GL" in os.environ:
        return os.environ["MUJOCO_GL"]
    for backend, library in (("egl", "EGL"), ("osmesa", "OSMesa")):
        if ctypes.util.find_library(library):
            return backend
    return "glfw" if has_display() else None


class FrameStrip(NamedTuple):
    """A drawn strip of postures, or why none was drawn."""

    path: Path | None
    """The PNG written; None when none could be."""
    reason: str
    """Why none was drawn ("" when one was)."""


def frame_strip(object_mass: float, qpos: np.ndarray, path: str | Path, markers=(), frames: int = 6) -> FrameStrip:
    """Draw `frames` evenly spaced postures of qpos (K, 7) of the Panda carrying object_mass (kg) side by
    side into a PNG at path, green spheres at the markers (each (3,), m), in a child process.

    Returns the strip's path, or None and the reason when offscreen rendering is not available here.
    """
    backend = headless_backend()
    if backend is None:
        return FrameStrip(None, "no offscreen OpenGL backend (EGL or OSMesa) and no display")
    with tempfile.TemporaryDirectory() as folder:
        inputs = Path(folder) / "frames.npz"
        np.savez(inputs, object_mass=object_mass, qpos=np.asarray(qpos)[np.linspace(0, len(qpos) - 1, frames).astype(int)],
                 markers=np.asarray(markers, dtype=float).reshape(-1, 3))
        child = subprocess.run([sys.executable, "-m", "comanip.simulation.rendering", str(inputs), str(path)],
                               env=os.environ | {"MUJOCO_GL": backend}, capture_output=True, text=True, timeout=300)
    if child.returncode != 0 or not Path(path).exists():
        lines = (child.stderr or child.stdout).strip().splitlines()
        return FrameStrip(None, f"offscreen rendering with MUJOCO_GL={backend} failed: {lines[-1] if lines else f'exit {child.returncode}'}")
    return FrameStrip(Path(path), "")


def render_frames(model, qpos: np.ndarray, path: str | Path, markers=(), size: tuple[int, int] = (240, 320)) -> Path:
    """Render every posture of qpos (F, nq) side by side into a PNG (in this process: MUJOCO_GL must already
    suit the machine), with green spheres at the markers (each (3,), m)."""
    import matplotlib.pyplot as plt
    import mujoco

    renderer = mujoco.Renderer(model, *size)
    data = mujoco.MjData(model)
    camera = mujoco.MjvCamera()
    camera.lookat[:] = [0.4, 0.15, 0.3]
    camera.distance, camera.azimuth, camera.elevation = 1.4, 140.0, -20.0
    images = []
    with renderer:
        for posture in qpos:
            data.qpos[:] = posture
            mujoco.mj_forward(model, data)
            renderer.update_scene(data, camera)
            for position in markers:
                _add_sphere(renderer.scene, position, 0.02, (0.1, 0.8, 0.2, 0.8))
            images.append(renderer.render().copy())
    plt.imsave(path, np.concatenate(images, axis=1))
    return Path(path)


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


if __name__ == "__main__":
    from comanip.simulation.panda_model import build_panda_model

    frames_file, png = sys.argv[1:3]
    with np.load(frames_file) as inputs:
        render_frames(build_panda_model(float(inputs["object_mass"])), inputs["qpos"], png, markers=inputs["markers"])

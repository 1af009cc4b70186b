"""Headless pictures of an environment (pybullet's TinyRenderer: CPU only, no display needed).

The default view looks at robot and person from the front-right, as the paper's figures do.
Targets with a ``show_rgba`` are drawn as small spheres (visual only, never collide).
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

DEFAULT_VIEW = {"eye": (-0.85, -1.35, 1.45), "target": (-0.12, -0.15, 0.85), "fov": 50.0}
"""World-frame camera: in front of the seated person (who faces −Y) and on the robot's side (−X)."""


def _place_markers(env) -> None:
    c = env.world.client
    for name, body in env.world.markers.items():
        pb.resetBasePositionAndOrientation(body, env.snap.position(env.snap.point({"target": name})).tolist(), (0, 0, 0, 1), physicsClientId=c)
    env.markers.place_visuals()
    env.particles.place_visuals()


def render_rgb(env, width: int = 480, height: int = 360, view: dict | None = None) -> np.ndarray:
    """An (height, width, 3) uint8 image of the env's current state."""
    v = DEFAULT_VIEW | (view or {})
    c = env.world.client
    _place_markers(env)
    view_m = pb.computeViewMatrix(v["eye"], v["target"], [0, 0, 1], physicsClientId=c)
    proj = pb.computeProjectionMatrixFOV(v["fov"], width / height, 0.02, 10.0, physicsClientId=c)
    _, _, rgba, _, _ = pb.getCameraImage(width, height, view_m, proj, renderer=pb.ER_TINY_RENDERER, lightDirection=[1, -1.5, 2],
                                         shadow=0, physicsClientId=c)
    return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]

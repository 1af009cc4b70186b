"""Headless pictures of an environment (pybullet's TinyRenderer: CPU only, no display needed).

**A render never changes the simulation.** It only reads the world: one ``getCameraImage``, then
the things drawn for people only — shown targets (e.g. the itch), markers not yet wiped, water
carried in a cup — are painted onto the picture as shaded dots, hidden where the depth buffer
says something is in front. They are not bodies: moving even a collision-less body reorders
Bullet's broadphase, and with it the contact solver, so a rendered episode would drift from an
unrendered one with the same seed.

The camera is the task's (``camera:`` in the spec, per robot; compiled into the manifest), or one
given per call (:func:`render_rgb`'s ``view``).
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

NEAR_M, FAR_M = 0.02, 10.0
"""Clipping planes of every render, m."""
TARGET_RADIUS_M = 0.012
"""Radius of a shown target's dot, m."""
LIGHT_DIRECTION = (1.0, -1.5, 2.0)


def overlay_spheres(env) -> list[tuple[list[float], float, tuple]]:
    """(position m, radius m, rgba) of everything drawn for people only: shown targets, markers
    not yet cleared, carried particles."""
    m, snap = env.manifest, env.snap
    spheres = [(snap.position(snap.point({"target": name})).tolist(), TARGET_RADIUS_M, tuple(t.show_rgba))
                for name, t in m.targets.items() if t.show_rgba is not None]
    return spheres + env.markers.visual_spheres() + env.particles.visual_spheres()


def camera_matrices(view: dict, width: int, height: int, client: int) -> tuple[list[float], list[float]]:
    """pybullet's (view, projection) matrices for ``view`` (eye, target in world m; fov_deg vertical)."""
    view_m = pb.computeViewMatrix(list(view["eye"]), list(view["target"]), [0, 0, 1], physicsClientId=client)
    proj = pb.computeProjectionMatrixFOV(view["fov_deg"], width / height, NEAR_M, FAR_M, physicsClientId=client)
    return view_m, proj


def render_rgb(env, width: int = 480, height: int = 360, view: dict | None = None) -> np.ndarray:
    """An (height, width, 3) uint8 image of the env's current state from the task's camera for
    its robot (``view``: eye / target / fov_deg overriding it)."""
    v = env.manifest.camera.model_dump() | (view or {})
    c = env.world.client
    view_m, proj = camera_matrices(v, width, height, c)
    _, _, rgba, depth, _ = pb.getCameraImage(width, height, view_m, proj, renderer=pb.ER_TINY_RENDERER,
                                             lightDirection=list(LIGHT_DIRECTION), shadow=0, physicsClientId=c)
    image = np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy()
    depth = np.asarray(depth, dtype=np.float64).reshape(height, width)
    draw_spheres(image, depth, overlay_spheres(env), view_m, proj)
    return image


def draw_spheres(image: np.ndarray, depth: np.ndarray, spheres, view_m, proj) -> None:
    """Paint each (position, radius, rgba) sphere onto ``image`` in place, shaded, where nothing in
    the depth buffer (pybullet's, in [0, 1]) is nearer than the sphere's front."""
    height, width = depth.shape
    to_clip = np.asarray(proj, dtype=np.float64).reshape(4, 4).T @ np.asarray(view_m, dtype=np.float64).reshape(4, 4).T
    scene_m = FAR_M * NEAR_M / (FAR_M - (FAR_M - NEAR_M) * depth)  # distance along the view axis, m
    rows, cols = np.mgrid[0:height, 0:width]
    for pos, radius, rgba in spheres:
        clip = to_clip @ np.array([*pos, 1.0])
        w = clip[3]  # distance along the view axis, m
        if w <= NEAR_M + radius:
            continue
        x = (clip[0] / w + 1.0) / 2.0 * width
        y = (1.0 - clip[1] / w) / 2.0 * height
        r_px = max(1.5, radius * to_clip[1, 1] * height / 2.0 / w)
        d2 = ((cols + 0.5 - x) ** 2 + (rows + 0.5 - y) ** 2) / r_px**2
        inside = (d2 <= 1.0) & (scene_m >= w - radius)
        if not inside.any():
            continue
        shade = 0.55 + 0.45 * np.sqrt(np.clip(1.0 - d2[inside], 0.0, 1.0))
        image[inside] = np.clip(np.outer(shade, np.asarray(rgba[:3]) * 255.0), 0, 255).astype(np.uint8)

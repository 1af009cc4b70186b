"""Headless pictures of an environment (pybullet's TinyRenderer: CPU only, no display needed).

**A render never changes the simulation.** It only reads the world: one ``getCameraImage``, then
the things drawn for people only — shown targets (e.g. the itch), markers not yet wiped, water
carried in a cup — are painted onto the picture as shaded dots, hidden where the depth buffer
says something is in front.

Garments (soft bodies) are drawn the same way, from their simulation nodes: TinyRenderer's copy of a
soft body's mesh is refreshed only by a physics step, so right after ``reset`` (which puts the
nodes back with ``resetMeshData``) it would draw the cloth where it was before. The renderer hides
the soft body from ``getCameraImage`` (its colour's alpha set to 0, restored after: a visual
property only) and rasterises the nodes' triangles onto the picture with the depth buffer. They are not bodies: moving even a collision-less body reorders
Bullet's broadphase, and with it the contact solver, so a rendered episode would drift from an
unrendered one with the same seed.

The camera is the task's (``camera:`` in the spec, per robot; compiled into the manifest), or one
given per call (:func:`render_rgb`'s ``view``).
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..artifact import Camera
from ..references import TargetPoint

NEAR_M, FAR_M = 0.02, 10.0
"""Clipping planes of every render, m."""
TARGET_RADIUS_M = 0.012
"""Radius of a shown target's dot, m."""
LIGHT_DIRECTION = (1.0, -1.5, 2.0)


def overlay_spheres(env) -> list[tuple[list[float], float, tuple]]:
    """(position m, radius m, rgba) of everything drawn for people only: shown targets, markers
    not yet cleared, carried particles."""
    m, snap = env.manifest, env.snap
    spheres = [
        (snap.position(snap.point(TargetPoint(target=name))).tolist(), TARGET_RADIUS_M, tuple(t.show_rgba))
        for name, t in m.targets.items()
        if t.show_rgba is not None
    ]
    return spheres + env.markers.visual_spheres() + env.particles.visual_spheres()


def camera_matrices(view: Camera, width: int, height: int, client: int) -> tuple[list[float], list[float]]:
    """pybullet's (view, projection) matrices for ``view`` (eye, target in world m; fov_deg vertical)."""
    view_m = pb.computeViewMatrix(list(view.eye), list(view.target), [0, 0, 1], physicsClientId=client)
    proj = pb.computeProjectionMatrixFOV(view.fov_deg, width / height, NEAR_M, FAR_M, physicsClientId=client)
    return view_m, proj


def render_rgb(env, width: int = 480, height: int = 360, view: dict | None = None) -> np.ndarray:
    """An (height, width, 3) uint8 image of the env's current state from the task's camera for
    its robot (``view``: eye / target / fov_deg overriding it)."""
    v = env.manifest.camera.model_copy(update=view or {})
    w = env.world
    c = w.client
    view_m, proj = camera_matrices(v, width, height, c)
    for g in w.garments:  # TinyRenderer's soft-body mesh may be stale (see the module doc)
        pb.changeVisualShape(g.soft_id, -1, rgbaColor=[*g.rgba[:3], 0.0], physicsClientId=c)
    try:
        _, _, rgba, depth, _ = pb.getCameraImage(
            width,
            height,
            view_m,
            proj,
            renderer=pb.ER_TINY_RENDERER,
            lightDirection=list(LIGHT_DIRECTION),
            shadow=0,
            physicsClientId=c,
        )
    finally:
        for g in w.garments:
            pb.changeVisualShape(g.soft_id, -1, rgbaColor=list(g.rgba), physicsClientId=c)
    image = np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy()
    depth = np.asarray(depth, dtype=np.float64).reshape(height, width)
    for g in w.garments:
        draw_mesh(image, depth, w.garment_nodes(g), g.faces, g.rgba, view_m, proj)
    draw_spheres(image, depth, overlay_spheres(env), view_m, proj)
    if getattr(env, "show_frames", False):
        draw_frames(image, labelled_frames(env), view_m, proj)
    return image


FRAME_AXIS_M = 0.06
"""Length of each drawn frame axis, m."""
AXIS_COLOURS = ((230, 40, 40), (40, 190, 40), (50, 90, 240))
"""x red, y green, z blue (the usual convention)."""


def labelled_frames(env) -> list[tuple[str, np.ndarray, np.ndarray | None]]:
    """(label, world position m, 3×3 rotation or None) of what a spec refers to most: the robot's
    end effector, each tool's named links, each target (a point: no axes)."""
    from ..rotation import quat_matrix

    m, w, snap = env.manifest, env.world, env.snap
    out = []
    ee = m.robot.links.get("end_effector")
    if ee is not None:
        pos, orn = w.link_frame(w.robot, w.robot.links[ee])
        out.append((f"robot.{ee}", np.asarray(pos), quat_matrix(orn)))
    for tool in m.tools:
        handle = w.bodies[tool.body]
        for name, link in sorted(tool.links.items()):
            if name == "base" and list(tool.links.values()).count(link) > 1:
                continue  # the base is also a named link: drawn once, by its name
            pos, orn = w.link_frame(handle, handle.links[link])
            out.append((f"{tool.body}.{name}", np.asarray(pos), quat_matrix(orn)))
    for name in m.targets:
        out.append((name, np.asarray(snap.position(snap.point(TargetPoint(target=name)))), None))
    return out


def draw_frames(image: np.ndarray, frames, view_m, proj) -> None:
    """Draw each frame's axes (x red, y green, z blue, :data:`FRAME_AXIS_M` long) and its label onto
    ``image`` in place, over everything (an annotation, not part of the scene)."""
    from PIL import Image, ImageDraw

    height, width = image.shape[:2]
    to_clip = clip_transform(view_m, proj)
    picture = Image.fromarray(image)
    draw = ImageDraw.Draw(picture)
    labels: list[tuple[np.ndarray, list[str]]] = []  # frames within 1.5 cm share one label
    for label, pos, _ in frames:
        near = next((entry for entry in labels if np.linalg.norm(entry[0] - pos) < 0.015), None)
        if near is None:
            labels.append((np.asarray(pos, dtype=float), [label]))
        else:
            near[1].append(label)
    for _label, pos, rot in frames:
        ends = [pos] + ([pos + FRAME_AXIS_M * rot[:, k] for k in range(3)] if rot is not None else [])
        px, w = to_pixels(np.asarray(ends), to_clip, width, height)
        if (w <= NEAR_M).any():
            continue
        origin = tuple(px[0])
        for k in range(1, len(ends)):
            draw.line([origin, tuple(px[k])], fill=AXIS_COLOURS[k - 1], width=2)
        if rot is None:
            draw.ellipse([origin[0] - 3, origin[1] - 3, origin[0] + 3, origin[1] + 3], outline=(0, 0, 0), width=1)
    for pos, names in labels:  # on a white box, readable over a dark robot
        px, w = to_pixels(np.asarray([pos]), to_clip, width, height)
        if w[0] <= NEAR_M:
            continue
        text = " / ".join(names)
        at = (float(px[0, 0]) + 5, float(px[0, 1]) + 3)
        box = draw.textbbox(at, text)
        draw.rectangle([box[0] - 1, box[1] - 1, box[2] + 1, box[3] + 1], fill=(255, 255, 255))
        draw.text(at, text, fill=(0, 0, 0))
    image[...] = np.asarray(picture)


def clip_transform(view_m, proj) -> np.ndarray:
    """4×4 world → clip-space matrix of pybullet's (column-major) view and projection matrices."""
    return np.asarray(proj, dtype=np.float64).reshape(4, 4).T @ np.asarray(view_m, dtype=np.float64).reshape(4, 4).T


def to_pixels(points, to_clip: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Image coordinates (column, row; pixels, origin at the top-left corner) of world-frame
    ``points`` (n × 3, m) under the world → clip matrix ``to_clip``, and each point's distance
    along the view axis (m; the clip-space w)."""
    clip = np.c_[np.asarray(points, dtype=np.float64).reshape(-1, 3), np.ones(len(points))] @ to_clip.T
    w = clip[:, 3]
    return np.stack([(clip[:, 0] / w + 1.0) / 2.0 * width, (1.0 - clip[:, 1] / w) / 2.0 * height], axis=1), w


def _view_distance_m(depth: np.ndarray) -> np.ndarray:
    """Distance along the view axis, m, of pybullet's depth buffer values (in [0, 1])."""
    return FAR_M * NEAR_M / (FAR_M - (FAR_M - NEAR_M) * depth)


def draw_mesh(
    image: np.ndarray, depth: np.ndarray, vertices: np.ndarray, faces: np.ndarray, rgba, view_m, proj
) -> None:
    """Paint a triangle mesh (world-frame ``vertices`` m, ``faces`` vertex indices) onto ``image``
    in place, flat shaded from both sides and blended by ``rgba``'s alpha, where it is nearer
    than the depth buffer; ``depth`` is updated where it is drawn."""
    height, width = depth.shape
    px, w = to_pixels(vertices, clip_transform(view_m, proj), width, height)
    scene_m = _view_distance_m(depth)
    light = np.asarray(LIGHT_DIRECTION, dtype=np.float64) / np.linalg.norm(LIGHT_DIRECTION)
    colour, alpha = np.asarray(rgba[:3], dtype=np.float64) * 255.0, float(rgba[3])
    faces = np.asarray(faces)
    for tri in faces[np.argsort(-w[faces].mean(axis=1), kind="stable")]:  # far to near: the front blends over the back
        if (w[tri] <= NEAR_M).any():
            continue
        (ax, ay), (bx, by), (cx, cy) = px[tri]
        area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        if abs(area) < 1e-12:
            continue
        c0, c1 = max(int(np.floor(px[tri, 0].min())), 0), min(int(np.ceil(px[tri, 0].max())), width)
        r0, r1 = max(int(np.floor(px[tri, 1].min())), 0), min(int(np.ceil(px[tri, 1].max())), height)
        if c0 >= c1 or r0 >= r1:
            continue
        ys, xs = np.mgrid[r0:r1, c0:c1] + 0.5
        l1 = ((cx - bx) * (ys - by) - (cy - by) * (xs - bx)) / area  # barycentric weight of vertex a
        l2 = ((ax - cx) * (ys - cy) - (ay - cy) * (xs - cx)) / area  # of vertex b
        l3 = 1.0 - l1 - l2
        inside = (l1 >= 0) & (l2 >= 0) & (l3 >= 0)
        inv_w = l1 / w[tri[0]] + l2 / w[tri[1]] + l3 / w[tri[2]]  # 1/w is linear on the screen
        dist = 1.0 / np.where(inside, inv_w, 1.0)
        block = scene_m[r0:r1, c0:c1]
        inside &= dist < block
        if not inside.any():
            continue
        a, b, c = np.asarray(vertices, dtype=np.float64)[tri]
        normal = np.cross(b - a, c - a)
        shade = 0.55 + 0.45 * abs(float(normal @ light)) / max(float(np.linalg.norm(normal)), 1e-12)
        region = image[r0:r1, c0:c1]
        region[inside] = np.clip((1.0 - alpha) * region[inside] + alpha * shade * colour, 0, 255).astype(np.uint8)
        block[inside] = dist[inside]
        depth[r0:r1, c0:c1][inside] = (FAR_M - FAR_M * NEAR_M / dist[inside]) / (FAR_M - NEAR_M)


def draw_spheres(image: np.ndarray, depth: np.ndarray, spheres, view_m, proj) -> None:
    """Paint each (position, radius, rgba) sphere onto ``image`` in place, shaded, where nothing in
    the depth buffer (pybullet's, in [0, 1]) is nearer than the sphere's front."""
    height, width = depth.shape
    to_clip = clip_transform(view_m, proj)
    scene_m = _view_distance_m(depth)  # distance along the view axis, m
    rows, cols = np.mgrid[0:height, 0:width]
    if not spheres:
        return
    centres_px, distances_m = to_pixels([pos for pos, _, _ in spheres], to_clip, width, height)
    for (x, y), w, (_, radius, rgba) in zip(centres_px, distances_m, spheres):
        if w <= NEAR_M + radius:
            continue
        r_px = max(1.5, radius * to_clip[1, 1] * height / 2.0 / w)
        d2 = ((cols + 0.5 - x) ** 2 + (rows + 0.5 - y) ** 2) / r_px**2
        inside = (d2 <= 1.0) & (scene_m >= w - radius)
        if not inside.any():
            continue
        shade = 0.55 + 0.45 * np.sqrt(np.clip(1.0 - d2[inside], 0.0, 1.0))
        image[inside] = np.clip(np.outer(shade, np.asarray(rgba[:3]) * 255.0), 0, 255).astype(np.uint8)

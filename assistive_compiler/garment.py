"""Garment meshes for the dressing task: a hospital-gown sleeve as an open triangulated tube.

Pure functions on numpy arrays; no physics-engine import.  The mesh is written as an OBJ that
stock PyBullet loads with ``loadSoftBody`` (each OBJ vertex becomes one soft-body node, in file
order, so the vertex indices below are also the node indices of the loaded soft body).

Sleeve frame (metres)
---------------------
* The tube axis is **+z**.  Ring ``0`` — the **opening** through which the hand enters — lies in
  the plane ``z = 0``, centred on the origin; ring ``rings - 1`` (the cuff end) lies at
  ``z = length_m``.
* Rings are equally spaced along z.  The radius varies linearly from ``radius_open_m`` (ring 0)
  to ``radius_end_m`` (last ring), so a sleeve may narrow towards its cuff.
* Vertex ``k = ring * segments + j`` sits at angle ``theta_j = 2*pi*j / segments`` measured from
  +x towards +y: ``(r cos theta_j, r sin theta_j, z_ring)``.  So segment ``j = segments / 4``
  is on +y and ``j = 0`` on +x.
* Both ends are open (no caps).  Triangles wind counter-clockwise seen from **outside** the tube
  (outward normals).

To dress an arm pulling the opening hand → shoulder, place the sleeve so that +z points from
the shoulder towards (and beyond) the hand: the tube body trails beyond the hand and the arm
slides into the opening, along the inside of the tube.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = [
    "sleeve_mesh",
    "write_obj",
    "ring_indices",
    "opening_ring_indices",
    "gripped_ring_indices",
    "ring_centre",
    "boundary_edges",
]


def sleeve_mesh(
    length_m: float,
    radius_open_m: float,
    radius_end_m: float | None = None,
    rings: int = 11,
    segments: int = 12,
) -> tuple[np.ndarray, np.ndarray]:
    """Vertices ``(rings*segments, 3)`` float64 and faces ``(2*(rings-1)*segments, 3)`` int64.

    ``radius_end_m`` defaults to ``radius_open_m`` (a straight tube).  ``rings >= 2`` rings of
    ``segments >= 3`` vertices; see the module docstring for the frame and index layout.
    """
    if radius_end_m is None:
        radius_end_m = radius_open_m
    if rings < 2 or segments < 3:
        raise ValueError(f"need rings >= 2 and segments >= 3, got rings={rings}, segments={segments}")
    if length_m <= 0 or radius_open_m <= 0 or radius_end_m <= 0:
        raise ValueError("length and radii must be positive")
    z = np.linspace(0.0, float(length_m), rings)
    r = np.linspace(float(radius_open_m), float(radius_end_m), rings)
    theta = 2.0 * np.pi * np.arange(segments) / segments
    verts = np.empty((rings, segments, 3))
    verts[:, :, 0] = r[:, None] * np.cos(theta)[None, :]
    verts[:, :, 1] = r[:, None] * np.sin(theta)[None, :]
    verts[:, :, 2] = z[:, None]
    verts = verts.reshape(-1, 3)
    # Quad (i, j) has corners a=(i,j), b=(i,j+1), c=(i+1,j+1), d=(i+1,j).  Going a→b is +theta
    # and a→d is +z, so (b-a)×(d-a) ∝ θ̂×ẑ = r̂: triangles (a,b,c) and (a,c,d) face outwards.
    i = np.arange(rings - 1)[:, None]
    j = np.arange(segments)[None, :]
    jn = (j + 1) % segments
    a = i * segments + j
    b = i * segments + jn
    c = (i + 1) * segments + jn
    d = (i + 1) * segments + j
    tri1 = np.stack([a, b, c], axis=-1).reshape(-1, 3)
    tri2 = np.stack([a, c, d], axis=-1).reshape(-1, 3)
    faces = np.stack([tri1, tri2], axis=1).reshape(-1, 3).astype(np.int64)
    return verts, faces


def write_obj(path: str | Path, vertices: np.ndarray, faces: np.ndarray, *, name: str = "sleeve") -> Path:
    """Write a deterministic Wavefront OBJ (``v`` lines with 6 decimals, 1-based ``f`` lines).

    The same arrays always give byte-identical files.  No normals or texture coordinates
    (PyBullet's soft-body loader does not need them).  Returns the path.
    """
    path = Path(path)
    vertices = np.asarray(vertices, dtype=float)
    faces = np.asarray(faces, dtype=np.int64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError("vertices must be (N, 3) and faces (M, 3)")
    if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise ValueError("face index out of range")
    lines = [f"# {name}: {len(vertices)} vertices, {len(faces)} triangles (assistive_compiler.garment)", f"o {name}"]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def ring_indices(ring: int, segments: int) -> np.ndarray:
    """Vertex (= soft-body node) indices of ring ``ring``, in increasing angle."""
    return ring * segments + np.arange(segments)


def opening_ring_indices(segments: int) -> np.ndarray:
    """Indices of the opening ring (ring 0, at z = 0)."""
    return ring_indices(0, segments)


def gripped_ring_indices(segments: int, ring: int = 0, arc_deg: float | None = None, centre_deg: float = 90.0) -> np.ndarray:
    """Indices of the nodes a gripper holds.

    ``arc_deg=None`` → the whole ring ``ring`` (the gripper holds the opening like a hoop, which
    keeps it open).  Otherwise only the nodes of that ring whose angle lies within
    ``±arc_deg/2`` of ``centre_deg`` (default 90° = the +y side of the sleeve frame; orient the
    sleeve so that side is up to model a gripper pinching the top of the rim).
    """
    idx = ring_indices(ring, segments)
    if arc_deg is None:
        return idx
    theta = np.degrees(2.0 * np.pi * np.arange(segments) / segments)
    diff = (theta - centre_deg + 180.0) % 360.0 - 180.0
    return idx[np.abs(diff) <= arc_deg / 2.0 + 1e-9]


def ring_centre(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Mean of ``positions[indices]`` (e.g. the opening centre from the soft body's node positions)."""
    return np.asarray(positions, dtype=float)[np.asarray(indices)].mean(axis=0)


def boundary_edges(faces: np.ndarray) -> set[tuple[int, int]]:
    """Undirected edges used by exactly one face (for an open tube: the two end rings)."""
    counts: dict[tuple[int, int], int] = {}
    for f in np.asarray(faces):
        for u, v in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
            e = (int(min(u, v)), int(max(u, v)))
            counts[e] = counts.get(e, 0) + 1
    return {e for e, n in counts.items() if n == 1}

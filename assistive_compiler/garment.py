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
    "sleeve_node_sets",
    "ring_encloses_segment",
    "sleeve_progress",
    "load_garment",
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


def read_obj_faces(path: str | Path) -> np.ndarray:
    """(M, 3) 0-based vertex indices of an OBJ's triangles (``f`` lines as :func:`write_obj` writes
    them; ``v/vt/vn`` forms keep their vertex index)."""
    faces = [
        [int(tok.split("/")[0]) - 1 for tok in line.split()[1:4]]
        for line in Path(path).read_text().splitlines()
        if line.startswith("f ")
    ]
    return np.asarray(faces, dtype=np.int64).reshape(-1, 3)


def ring_indices(ring: int, segments: int) -> np.ndarray:
    """Vertex (= soft-body node) indices of ring ``ring``, in increasing angle."""
    return ring * segments + np.arange(segments)


def opening_ring_indices(segments: int) -> np.ndarray:
    """Indices of the opening ring (ring 0, at z = 0)."""
    return ring_indices(0, segments)


def gripped_ring_indices(
    segments: int, ring: int = 0, arc_deg: float | None = None, centre_deg: float = 90.0
) -> np.ndarray:
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


def sleeve_node_sets(rings: int, segments: int) -> dict[str, np.ndarray]:
    """The named node sets a generated sleeve exports (specs refer to them as ``<garment>.<set>``).

    * ``opening`` — ring 0, the hole the hand enters (whole ring, in increasing angle);
    * ``opening_top`` — the nodes of ring 0 within ±45° of the sleeve frame's +y (a pinch of the rim);
    * ``cuff`` — the last ring, at the far end of the tube.
    """
    return {
        "opening": opening_ring_indices(segments),
        "opening_top": gripped_ring_indices(segments, 0, arc_deg=90.0),
        "cuff": ring_indices(rings - 1, segments),
    }


def ring_encloses_segment(ring_xyz: np.ndarray, a: np.ndarray, b: np.ndarray) -> bool:
    """True when segment a→b passes through the closed polygon of the ring's nodes (in order).

    The ring's best-fit plane (SVD of the nodes about their mean); the segment must cross it, and
    the crossing point must have winding number ±1 with respect to the ring projected onto the
    plane. Any frame (all points in the same one), metres.
    """
    ring = np.asarray(ring_xyz, dtype=float)
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    c = ring.mean(axis=0)
    _, _, vt = np.linalg.svd(ring - c)
    n, e1, e2 = vt[2], vt[0], vt[1]
    da, db = float(np.dot(a - c, n)), float(np.dot(b - c, n))
    if da * db > 0 or da == db:
        return False
    x = a + (b - a) * (da / (da - db))
    q = np.stack([(ring - x) @ e1, (ring - x) @ e2], axis=1)
    ang = np.arctan2(q[:, 1], q[:, 0])
    dang = np.diff(np.append(ang, ang[0]))
    dang = (dang + np.pi) % (2 * np.pi) - np.pi
    return bool(abs(dang.sum()) > np.pi)


def _unit(v: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else v


def sleeve_progress(
    ring_xyz: np.ndarray,
    shoulder: np.ndarray,
    elbow: np.ndarray,
    wrist: np.ndarray,
    hand_beyond_wrist_m: float,
    beyond_elbow_m: float,
    beyond_shoulder_m: float,
    upper_arm_counts: bool = True,
) -> float:
    """The reference's dressing reward r_dress (paper §III-B), in metres, for one arm.

    ``upper_arm_counts=False`` skips the upper-arm branch (for a caller that requires the forearm
    to have been in the sleeve first: see the ``sleeve_progress`` reward term).

    Arm geometry (world frame, metres): ``hand_end = wrist + hand_beyond_wrist_m·û(wrist − elbow)``,
    ``elbow_end = elbow + beyond_elbow_m·û(elbow − wrist)``,
    ``shoulder_end = shoulder + beyond_shoulder_m·û(shoulder − elbow)`` (the reference: 2·r, r, r
    with r the upper-arm radius). The opening is ``ring_xyz`` (its nodes in order), its centre
    their mean. A limb is *in the sleeve* when its axis segment passes through the opening
    (:func:`ring_encloses_segment`; the reference uses two triangles of the ring instead).

    * upper arm (elbow_end→shoulder_end) in: ``forearm_len`` (= ‖hand_end − elbow_end‖) plus
      ‖centre − elbow‖ when that is below ``upperarm_len`` (= ‖elbow − shoulder‖);
    * else forearm (hand_end→elbow_end) in and ‖centre − hand_end‖ < forearm_len: ‖centre − hand_end‖;
    * else −‖hand_end − centre‖ (approach the hand).
    """
    shoulder, elbow, wrist = (np.asarray(v, dtype=float) for v in (shoulder, elbow, wrist))
    ring = np.asarray(ring_xyz, dtype=float)
    hand_end = wrist + hand_beyond_wrist_m * _unit(wrist - elbow)
    elbow_end = elbow + beyond_elbow_m * _unit(elbow - wrist)
    shoulder_end = shoulder + beyond_shoulder_m * _unit(shoulder - elbow)
    centre = ring.mean(axis=0)
    forearm_len = float(np.linalg.norm(hand_end - elbow_end))
    upperarm_len = float(np.linalg.norm(elbow - shoulder))
    if upper_arm_counts and ring_encloses_segment(ring, elbow_end, shoulder_end):
        along = float(np.linalg.norm(centre - elbow))
        return forearm_len + (along if along < upperarm_len else 0.0)
    to_hand = float(np.linalg.norm(centre - hand_end))
    if ring_encloses_segment(ring, hand_end, elbow_end) and to_hand < forearm_len:
        return to_hand
    return -to_hand


def load_garment(
    pb, c: int, obj: str | Path, held_pos, held_orn, mass, margin, ks, kd, kb, friction, anchored, rgba=None
) -> tuple[int, int]:
    """Load a garment OBJ (vertices in the held frame) as a mass-spring soft body with its held
    frame at (held_pos, held_orn), world frame, and pin the ``anchored`` nodes to a massless,
    collision-free body placed at that frame (teleport that body to move them). The world must
    be a deformable one (``resetSimulation(RESET_USE_DEFORMABLE_WORLD)`` before anything was
    loaded). Returns (soft body id, anchor body id). Shared by the compiler (settling) and the runtime."""
    sb = pb.loadSoftBody(
        str(obj),
        basePosition=list(held_pos),
        baseOrientation=list(held_orn),
        scale=1.0,
        mass=mass,
        collisionMargin=margin,
        useMassSpring=1,
        useBendingSprings=1,
        useNeoHookean=0,
        springElasticStiffness=ks,
        springDampingStiffness=kd,
        springDampingAllDirections=1,
        springBendingStiffness=kb,
        useSelfCollision=0,
        frictionCoeff=friction,
        useFaceContact=1,
        physicsClientId=c,
    )
    if rgba is not None:
        pb.changeVisualShape(sb, -1, rgbaColor=list(rgba), flags=pb.VISUAL_SHAPE_DOUBLE_SIDED, physicsClientId=c)
    # Asleep, a soft body reports no contacts: keep it awake.
    pb.changeDynamics(sb, -1, activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING, physicsClientId=c)
    anchor = pb.createMultiBody(
        baseMass=0, basePosition=list(held_pos), baseOrientation=list(held_orn), physicsClientId=c
    )
    # The anchor's local point is taken from the node's position at this moment (the node lies at
    # held pose × its OBJ vertex), so the pinned nodes keep their place in the held frame.
    nodes = pb.getMeshData(sb, -1, flags=pb.MESH_DATA_SIMULATION_MESH, physicsClientId=c)[1]
    inv_pos, inv_orn = pb.invertTransform(list(held_pos), list(held_orn))
    for i in anchored:
        local, _ = pb.multiplyTransforms(inv_pos, inv_orn, nodes[int(i)], (0, 0, 0, 1))
        pb.createSoftBodyAnchor(sb, int(i), anchor, -1, list(local), physicsClientId=c)
    return sb, anchor

"""assistive_compiler.garment: the sleeve mesh, its OBJ, and the mesh as a stock-pybullet soft body."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pybullet as p
import pytest

from assistive_compiler import garment

RINGS, SEGMENTS = 11, 12
LENGTH, R_OPEN, R_END = 0.5, 0.09, 0.07


@pytest.fixture(scope="module")
def mesh():
    return garment.sleeve_mesh(LENGTH, R_OPEN, R_END, RINGS, SEGMENTS)


@pytest.fixture(scope="module")
def obj_path(mesh, tmp_path_factory):
    return garment.write_obj(tmp_path_factory.mktemp("sleeve") / "sleeve.obj", *mesh)


def _edges(faces):
    return Counter(
        tuple(sorted((int(u), int(v)))) for f in faces for u, v in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0]))
    )


def test_counts_and_dtypes(mesh):
    v, f = mesh
    assert v.shape == (RINGS * SEGMENTS, 3) and v.dtype == np.float64
    assert f.shape == (2 * (RINGS - 1) * SEGMENTS, 3) and np.issubdtype(f.dtype, np.integer)
    assert f.min() == 0 and f.max() == len(v) - 1
    assert all(len(set(tri)) == 3 for tri in f.tolist())  # no degenerate triangles


def test_tube_sides_are_a_manifold_with_two_boundary_rings(mesh):
    _, f = mesh
    counts = _edges(f)
    assert set(counts.values()) <= {1, 2}  # never more than two faces on an edge
    boundary = {e for e, n in counts.items() if n == 1}
    assert boundary == garment.boundary_edges(f)
    first, last = set(garment.ring_indices(0, SEGMENTS)), set(garment.ring_indices(RINGS - 1, SEGMENTS))
    # every boundary edge joins two neighbours on the opening or on the cuff ring; all others are interior
    assert len(boundary) == 2 * SEGMENTS
    for a, b in boundary:
        assert {a, b} <= first or {a, b} <= last
        assert (b - a) % SEGMENTS in (1, SEGMENTS - 1)
    # consistent orientation: each interior edge is traversed once in each direction
    directed = Counter((int(u), int(v)) for tri in f for u, v in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])))
    assert all(n == 1 for n in directed.values())


def test_normals_point_outwards(mesh):
    v, f = mesh
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(b - a, c - a)
    centroid = (a + b + c) / 3
    radial = centroid.copy()
    radial[:, 2] = 0.0
    assert (np.einsum("ij,ij->i", n, radial) > 0).all()


def test_opening_and_cuff_rings(mesh):
    v, _ = mesh
    op = garment.opening_ring_indices(SEGMENTS)
    assert np.allclose(v[op, 2], 0.0)
    assert np.allclose(np.linalg.norm(v[op, :2], axis=1), R_OPEN)
    assert np.allclose(garment.ring_centre(v, op), 0.0, atol=1e-12)
    cuff = garment.ring_indices(RINGS - 1, SEGMENTS)
    assert np.allclose(v[cuff, 2], LENGTH)
    assert np.allclose(np.linalg.norm(v[cuff, :2], axis=1), R_END)
    # vertex j of a ring sits at angle 2πj/segments from +x towards +y
    j = SEGMENTS // 4
    assert np.allclose(v[op[j]], [0.0, R_OPEN, 0.0], atol=1e-12)


def test_gripped_ring_indices():
    assert list(garment.gripped_ring_indices(SEGMENTS)) == list(range(SEGMENTS))
    top = garment.gripped_ring_indices(SEGMENTS, arc_deg=90.0)  # ±45° around +y: 60°, 90°, 120°
    assert list(top) == [2, 3, 4]
    assert list(garment.gripped_ring_indices(SEGMENTS, ring=2, arc_deg=1.0)) == [2 * SEGMENTS + 3]


def test_straight_tube_default_and_validation():
    v, _ = garment.sleeve_mesh(0.3, 0.05, rings=3, segments=6)
    assert np.allclose(np.linalg.norm(v[:, :2], axis=1), 0.05)
    with pytest.raises(ValueError):
        garment.sleeve_mesh(0.3, 0.05, rings=1, segments=6)
    with pytest.raises(ValueError):
        garment.sleeve_mesh(0.3, -0.05)


def test_obj_is_deterministic_and_round_trips(mesh, obj_path, tmp_path):
    again = garment.write_obj(tmp_path / "again.obj", *mesh)
    assert again.read_bytes() == obj_path.read_bytes()
    lines = obj_path.read_text().splitlines()
    vs = np.array([[float(x) for x in ln.split()[1:]] for ln in lines if ln.startswith("v ")])
    fs = np.array([[int(x) - 1 for x in ln.split()[1:]] for ln in lines if ln.startswith("f ")])
    assert np.allclose(vs, mesh[0], atol=1e-6)
    assert (fs == mesh[1]).all()


@pytest.fixture()
def deformable_client():
    cid = p.connect(p.DIRECT)
    p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD, physicsClientId=cid)
    yield cid
    p.disconnect(cid)


def _load(cid, obj_path, pos=(0.0, 0.0, 1.0), orn=(0.0, 0.0, 0.0, 1.0)):
    # The parameters docs/dressing-study.md found stable at a 0.02 s step with 4 sub-steps.
    return p.loadSoftBody(
        str(obj_path),
        basePosition=list(pos),
        baseOrientation=list(orn),
        scale=1.0,
        mass=0.1,
        collisionMargin=0.01,
        useMassSpring=1,
        useBendingSprings=1,
        useNeoHookean=0,
        springElasticStiffness=10.0,
        springDampingStiffness=0.002,
        springDampingAllDirections=1,
        springBendingStiffness=0.1,
        useSelfCollision=0,
        frictionCoeff=0.5,
        physicsClientId=cid,
    )


def _nodes(cid, body):
    n, x = p.getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH, physicsClientId=cid)
    return n, np.asarray(x)


def test_loads_as_pybullet_soft_body_node_per_vertex(deformable_client, mesh, obj_path):
    cid = deformable_client
    body = _load(cid, obj_path)
    n, x = _nodes(cid, body)
    assert n == len(mesh[0]) == len(x)
    assert np.allclose(x, mesh[0] + [0.0, 0.0, 1.0], atol=1e-5)  # node i == OBJ vertex i, same order


def test_hanging_sleeve_is_stable(deformable_client, obj_path):
    """50 physics steps (0.02 s, 4 sub-steps) hanging from an opening ring anchored to a kinematic body."""
    cid = deformable_client
    p.setTimeStep(0.02, physicsClientId=cid)
    p.setPhysicsEngineParameter(numSubSteps=4, physicsClientId=cid)
    p.setGravity(0, 0, -9.81, physicsClientId=cid)
    pos, orn = [0.0, 0.0, 1.0], p.getQuaternionFromEuler([math.pi / 2, 0.0, 0.0])  # axis horizontal
    body = _load(cid, obj_path, pos, orn)
    anchor = p.createMultiBody(baseMass=0, basePosition=pos, baseOrientation=orn, physicsClientId=cid)
    _, x0 = _nodes(cid, body)
    op = garment.opening_ring_indices(SEGMENTS)
    for i in op:
        local, _ = p.multiplyTransforms(*p.invertTransform(pos, orn), list(x0[i]), [0, 0, 0, 1])
        p.createSoftBodyAnchor(body, int(i), anchor, -1, list(local), physicsClientId=cid)
    for k in range(50):  # the gripper moves 1 mm per step, as a slow robot would
        p.resetBasePositionAndOrientation(anchor, [0.0, -0.001 * k, 1.0], orn, physicsClientId=cid)
        p.stepSimulation(physicsClientId=cid)
    _, x = _nodes(cid, body)
    assert np.isfinite(x).all()
    assert np.linalg.norm(x - [0.0, -0.049, 1.0], axis=1).max() < 0.6  # nothing flew away (tube length 0.5)
    assert x[:, 2].min() < 1.0 - R_OPEN - 0.02  # it sagged under gravity
    assert np.allclose(garment.ring_centre(x, op), [0.0, -0.049, 1.0], atol=1e-4)  # opening follows the anchor

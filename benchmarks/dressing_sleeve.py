"""Feasibility experiment: a gown sleeve pulled along a seated person's left arm on STOCK pybullet.

Two methods (see docs/dressing-study.md for the findings):

* ``--method softbody`` — a pybullet deformable (``loadSoftBody`` of a tube OBJ made by
  ``assistive_compiler.garment``, mass-spring model) in a ``RESET_USE_DEFORMABLE_WORLD`` world.
  The opening ring is anchored (``createSoftBodyAnchor``) to a massless, collision-free body that
  is teleported to the gripper pose before every physics step (the reference teleports its
  cloth anchor the same way).
* ``--method rings`` — an articulated chain of rigid hoops (each hoop one link made of boxes
  arranged in a circle) joined by spherical joints held by weak position motors; the first hoop
  is the multibody base, driven by a fixed constraint to the gripper pose (``changeConstraint``).

The arm is static: capsules (upper arm, forearm) + spheres (shoulder, elbow, wrist, hand) in one
fixed-base multibody.  The gripper moves the sleeve opening along the arm axis from 10 cm beyond
the hand end to the shoulder in ``--move-s`` seconds (after a short settle at g/2 as the
reference does), then holds.  Printed: stability (NaN, farthest node from the arm), whether the
arm axis passes through the opening ring, progress of the opening up the arm, contact forces
of the sleeve on the arm, and timing (physics steps/s, env steps/s = physics/5).

Run e.g.::

    .venv/bin/python benchmarks/dressing_sleeve.py --method softbody --pose bent --print
    .venv/bin/python benchmarks/dressing_sleeve.py --method rings --pose straight --repeat 3
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pybullet as p

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from assistive_compiler import garment  # noqa: E402

DT = 0.02
FRAME_SKIP = 5
SHOULDER = np.array([0.18, 0.0, 1.2])
R_UPPER, L_UPPER = 0.043, 0.279
R_FORE, L_FORE = 0.033, 0.257
R_HAND = 0.043


# ----------------------------------------------------------------------------- geometry


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def arm_points(pose: str) -> dict[str, np.ndarray]:
    """Shoulder, elbow, wrist, hand centre and the reference's hand_end / shoulder_end points.

    ``straight``: the whole arm horizontal, pointing forward (−y).  ``bent``: the reference pose
    (left shoulder_x −45°, elbow −90°): upper arm 45° forward-down, forearm 45° forward-up.
    """
    if pose == "straight":
        u1 = u2 = np.array([0.0, -1.0, 0.0])
    elif pose == "bent":
        a1, a2 = math.radians(45), math.radians(135)  # angle from straight down, swung forward
        u1 = np.array([0.0, -math.sin(a1), -math.cos(a1)])
        u2 = np.array([0.0, -math.sin(a2), -math.cos(a2)])
    else:
        raise ValueError(pose)
    s = SHOULDER
    e = s + L_UPPER * u1
    w = e + L_FORE * u2
    return {
        "shoulder": s,
        "elbow": e,
        "wrist": w,
        "hand": w + R_HAND * u2,
        "hand_end": w + 2 * R_HAND * u2,
        "shoulder_end": s - R_UPPER * u1,
        "u1": u1,
        "u2": u2,
    }


def _quat_z_to(d) -> list[float]:
    """Quaternion rotating +z onto direction d (shortest arc)."""
    d = _unit(d)
    z = np.array([0.0, 0.0, 1.0])
    c = float(np.dot(z, d))
    if c < -0.999999:
        return [1.0, 0.0, 0.0, 0.0]
    axis = np.cross(z, d)
    q = np.array([axis[0], axis[1], axis[2], 1.0 + c])
    return list(q / np.linalg.norm(q))


def _quat_frame(zdir, up_hint=(0.0, 0.0, 1.0)) -> list[float]:
    """Quaternion of a frame whose +z is ``zdir`` and whose +y is as close as possible to ``up_hint``.

    Used so the sleeve frame's +y side (garment angle 90°) — the side a pinch grip holds — is up.
    """
    z = _unit(zdir)
    up = np.asarray(up_hint, float)
    y = up - np.dot(up, z) * z
    if np.linalg.norm(y) < 1e-6:
        y = np.array([1.0, 0.0, 0.0]) - z[0] * z
    y = _unit(y)
    x = np.cross(y, z)
    m = np.stack([x, y, z], axis=1)
    # rotation matrix → quaternion (x, y, z, w)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = [0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = [(m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s]
    return list(np.array(q) / np.linalg.norm(q))


class GripperPath:
    """Piecewise-linear opening path start → elbow → shoulder at constant speed.

    ``pose_at(t)`` gives the opening centre and the sleeve-frame quaternion: sleeve +z points
    back along the path (towards the hand, where the tube body trails), blended over ``blend``
    metres around the elbow so the hoop turns smoothly.
    """

    def __init__(self, pts, beyond=0.10, duration=10.0, blend=0.08):
        self.a = pts["hand_end"] + beyond * pts["u2"]
        self.nodes = [self.a, pts["elbow"], pts["shoulder"]]
        self.seg = [self.nodes[1] - self.nodes[0], self.nodes[2] - self.nodes[1]]
        self.lens = [float(np.linalg.norm(s)) for s in self.seg]
        self.total = sum(self.lens)
        self.duration = duration
        self.blend = blend

    def pose_at(self, t: float):
        s = min(max(t / self.duration, 0.0), 1.0) * self.total
        d0, d1 = -_unit(self.seg[0]), -_unit(self.seg[1])  # sleeve +z = back along the path
        if s <= self.lens[0]:
            pos = self.nodes[0] + self.seg[0] * (s / self.lens[0])
        else:
            pos = self.nodes[1] + self.seg[1] * ((s - self.lens[0]) / self.lens[1])
        w = np.clip((s - (self.lens[0] - self.blend)) / (2 * self.blend), 0.0, 1.0)
        zdir = _unit((1 - w) * d0 + w * d1)
        return pos, _quat_frame(zdir)


def arm_axis(pts) -> list[tuple[np.ndarray, np.ndarray]]:
    """Arm axis as segments, hand end first: hand_end→elbow, elbow→shoulder_end."""
    return [(pts["hand_end"], pts["elbow"]), (pts["elbow"], pts["shoulder_end"])]


def progress_along_arm(pts, c) -> float:
    """Arc length (m) from hand_end of the projection of point c onto the arm axis polyline."""
    best, acc, best_d = 0.0, 0.0, 1e9
    for a, b in arm_axis(pts):
        ab = b - a
        L = float(np.linalg.norm(ab))
        t = float(np.clip(np.dot(c - a, ab) / (L * L), 0.0, 1.0))
        d = float(np.linalg.norm(a + t * ab - c))
        if d < best_d:
            best_d, best = d, acc + t * L
        acc += L
    return best


def arm_length(pts) -> float:
    return sum(float(np.linalg.norm(b - a)) for a, b in arm_axis(pts))


def ring_encloses_arm(ring_xyz: np.ndarray, pts) -> bool:
    """True when some arm-axis segment passes through the (closed, ordered) ring polygon.

    Best-fit plane of the ring (SVD); the segment must cross that plane, and the crossing point
    must have a non-zero 2-D winding number w.r.t. the ring projected onto the plane.
    """
    c = ring_xyz.mean(axis=0)
    _, _, vt = np.linalg.svd(ring_xyz - c)
    n, e1, e2 = vt[2], vt[0], vt[1]
    for a, b in arm_axis(pts):
        da, db = np.dot(a - c, n), np.dot(b - c, n)
        if da * db > 0 or da == db:
            continue
        x = a + (b - a) * (da / (da - db))
        q = np.stack([(ring_xyz - x) @ e1, (ring_xyz - x) @ e2], axis=1)
        ang = np.arctan2(q[:, 1], q[:, 0])
        dang = np.diff(np.append(ang, ang[0]))
        dang = (dang + np.pi) % (2 * np.pi) - np.pi
        if abs(dang.sum()) > np.pi:  # winding number ±1
            return True
    return False


def penetration(xyz: np.ndarray, pts) -> float:
    """Deepest point inside the arm capsules (m, > 0 means inside; the hand sphere is ignored)."""
    worst = -np.inf
    for (a, b), r in zip(arm_axis(pts), (R_FORE, R_UPPER)):
        ab = b - a
        t = np.clip(((xyz - a) @ ab) / (ab @ ab), 0.0, 1.0)
        worst = max(worst, float((r - np.linalg.norm(a + t[:, None] * ab - xyz, axis=1)).max()))
    return worst


def dist_to_arm(xyz: np.ndarray, pts) -> np.ndarray:
    """Distance of each point to the arm axis polyline."""
    out = np.full(len(xyz), np.inf)
    for a, b in arm_axis(pts):
        ab = b - a
        t = np.clip(((xyz - a) @ ab) / (ab @ ab), 0.0, 1.0)
        out = np.minimum(out, np.linalg.norm(a + t[:, None] * ab - xyz, axis=1))
    return out


# ----------------------------------------------------------------------------- world


def build_arm(pts, cid) -> int:
    """Fixed multibody: base = upper-arm capsule, plus forearm capsule and joint spheres (all static)."""

    def capsule(a, b, r):
        return dict(
            shapeType=p.GEOM_CAPSULE,
            radius=r,
            length=float(np.linalg.norm(b - a)),
            pos=list((a + b) / 2),
            orn=_quat_z_to(b - a),
        )

    parts = [
        capsule(pts["shoulder"], pts["elbow"], R_UPPER),
        capsule(pts["elbow"], pts["wrist"], R_FORE),
        dict(shapeType=p.GEOM_SPHERE, radius=R_UPPER, length=0, pos=list(pts["shoulder"]), orn=[0, 0, 0, 1]),
        dict(shapeType=p.GEOM_SPHERE, radius=R_UPPER, length=0, pos=list(pts["elbow"]), orn=[0, 0, 0, 1]),
        dict(shapeType=p.GEOM_SPHERE, radius=R_FORE, length=0, pos=list(pts["wrist"]), orn=[0, 0, 0, 1]),
        dict(shapeType=p.GEOM_SPHERE, radius=R_HAND, length=0, pos=list(pts["hand"]), orn=[0, 0, 0, 1]),
    ]
    col = p.createCollisionShapeArray(
        shapeTypes=[q["shapeType"] for q in parts],
        radii=[q["radius"] for q in parts],
        lengths=[q["length"] for q in parts],
        collisionFramePositions=[q["pos"] for q in parts],
        collisionFrameOrientations=[q["orn"] for q in parts],
        physicsClientId=cid,
    )
    return p.createMultiBody(baseMass=0, baseCollisionShapeIndex=col, basePosition=[0, 0, 0], physicsClientId=cid)


SOFT_DEFAULTS = dict(
    mass=0.1,
    margin=0.01,
    ks=10.0,
    kd=0.002,
    kb=0.1,
    friction=0.5,
    substeps=4,
    damp_all=1,
    face_contact=1,
    sdf_voxel=0.25,
)


class SoftSleeve:
    """Method A: pybullet deformable tube anchored by its opening ring to a teleported body."""

    def __init__(self, cid, obj_path, rings, segments, pos, orn, grip="ring", **kw):
        cfg = {**SOFT_DEFAULTS, **kw}
        self.cid, self.segments = cid, segments
        self.sb = p.loadSoftBody(
            str(obj_path),
            basePosition=list(pos),
            baseOrientation=list(orn),
            scale=1.0,
            mass=cfg["mass"],
            collisionMargin=cfg["margin"],
            useMassSpring=1,
            useBendingSprings=1,
            useNeoHookean=0,
            springElasticStiffness=cfg["ks"],
            springDampingStiffness=cfg["kd"],
            springDampingAllDirections=cfg["damp_all"],
            springBendingStiffness=cfg["kb"],
            useSelfCollision=0,
            frictionCoeff=cfg["friction"],
            useFaceContact=cfg["face_contact"],
            physicsClientId=cid,
        )
        # Soft bodies fall asleep like rigid ones; asleep, they report no contacts — keep them awake.
        p.changeDynamics(self.sb, -1, activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING, physicsClientId=cid)
        self.anchor = p.createMultiBody(
            baseMass=0, basePosition=list(pos), baseOrientation=list(orn), physicsClientId=cid
        )
        x = self.nodes()
        arc = None if grip == "ring" else 90.0
        self.gripped = garment.gripped_ring_indices(segments, 0, arc_deg=arc)
        inv_p, inv_q = p.invertTransform(list(pos), list(orn))
        for i in self.gripped:
            local, _ = p.multiplyTransforms(inv_p, inv_q, list(x[i]), [0, 0, 0, 1])
            p.createSoftBodyAnchor(self.sb, int(i), self.anchor, -1, list(local), physicsClientId=cid)
        self.opening = garment.opening_ring_indices(segments)

    def nodes(self) -> np.ndarray:
        return np.asarray(p.getMeshData(self.sb, -1, flags=p.MESH_DATA_SIMULATION_MESH, physicsClientId=self.cid)[1])

    def reset_nodes(self, x0: np.ndarray):
        """Episode reset without reloading: restoreState does NOT cover soft-body nodes.

        ``resetMeshData`` sets every node position (0.05 ms for 132 nodes) and
        ``resetBaseVelocity(sb, 0, 0)`` zeroes every node velocity (without it the nodes keep
        the velocity they had).  Move the anchor body back first.
        """
        p.resetMeshData(self.sb, vertices=np.asarray(x0).tolist(), physicsClientId=self.cid)
        p.resetBaseVelocity(self.sb, [0, 0, 0], [0, 0, 0], physicsClientId=self.cid)

    def move_grip(self, pos, orn):
        p.resetBasePositionAndOrientation(self.anchor, list(pos), list(orn), physicsClientId=self.cid)

    def ring(self) -> np.ndarray:
        return self.nodes()[self.opening]

    def all_rings(self, x) -> list[np.ndarray]:
        return [x[garment.ring_indices(k, self.segments)] for k in range(len(x) // self.segments)]

    def bodies(self):
        return [self.sb]


RING_DEFAULTS = dict(n_rings=8, boxes=10, mass=0.1, joint_force=0.02, joint_gain=0.05, friction=0.1, overlap=0.4)


class RingSleeve:
    """Method B: chain of rigid hoops with weak spherical joints; hoop 0 follows the gripper.

    Hoop i is centred on the sleeve axis at z_i (sleeve frame, +z away from the opening); each
    hoop is ``boxes`` thin boxes tangent to a circle.  Joint between hoops i-1 and i is a
    spherical joint at hoop i's centre (so centres stay ``spacing`` apart, hoops tilt freely
    apart from the motor).  Hoop 0 is the multibody base, held by a JOINT_FIXED constraint to the
    world that is re-targeted each physics step.
    """

    def __init__(self, cid, length, r_open, r_end, pos, orn, **kw):
        cfg = {**RING_DEFAULTS, **kw}
        self.cid = cid
        n, nb = cfg["n_rings"], cfg["boxes"]
        zs = np.linspace(0.0, length, n)
        rs = np.linspace(r_open, r_end, n)
        self.spacing = zs[1] - zs[0]
        self.r_open = r_open
        m_ring = cfg["mass"] / n

        half_axial = cfg["overlap"] * self.spacing / 2  # >1 overlap: no gap between hoops for the arm to slip through

        def hoop(r):
            th = 2 * np.pi * np.arange(nb) / nb
            half_t = r * math.tan(math.pi / nb) * 1.05
            ext = [half_t, 0.004, half_axial]
            pos_ = [[r * math.cos(a), r * math.sin(a), 0.0] for a in th]
            orn_ = [p.getQuaternionFromEuler([0, 0, a + math.pi / 2]) for a in th]
            return p.createCollisionShapeArray(
                shapeTypes=[p.GEOM_BOX] * nb,
                halfExtents=[ext] * nb,
                collisionFramePositions=pos_,
                collisionFrameOrientations=orn_,
                physicsClientId=cid,
            )

        cols = [hoop(r) for r in rs]
        self.body = p.createMultiBody(
            baseMass=m_ring,
            baseCollisionShapeIndex=cols[0],
            basePosition=list(pos),
            baseOrientation=list(orn),
            linkMasses=[m_ring] * (n - 1),
            linkCollisionShapeIndices=cols[1:],
            linkVisualShapeIndices=[-1] * (n - 1),
            linkPositions=[[0, 0, self.spacing]] * (n - 1),
            linkOrientations=[[0, 0, 0, 1]] * (n - 1),
            linkInertialFramePositions=[[0, 0, 0]] * (n - 1),
            linkInertialFrameOrientations=[[0, 0, 0, 1]] * (n - 1),
            linkParentIndices=list(range(n - 1)),
            linkJointTypes=[p.JOINT_SPHERICAL] * (n - 1),
            linkJointAxis=[[0, 0, 1]] * (n - 1),
            physicsClientId=cid,
        )
        for j in range(-1, n - 1):
            p.changeDynamics(
                self.body,
                j,
                lateralFriction=cfg["friction"],
                linearDamping=0.5,
                angularDamping=0.5,
                physicsClientId=cid,
            )
        f = cfg["joint_force"]
        for j in range(n - 1):
            p.setJointMotorControlMultiDof(
                self.body,
                j,
                p.POSITION_CONTROL,
                targetPosition=[0, 0, 0, 1],
                targetVelocity=[0, 0, 0],
                positionGain=cfg["joint_gain"],
                velocityGain=1.0,
                force=[f, f, f],
                physicsClientId=cid,
            )
        self.cons = p.createConstraint(
            self.body,
            -1,
            -1,
            -1,
            p.JOINT_FIXED,
            [0, 0, 0],
            [0, 0, 0],
            list(pos),
            childFrameOrientation=list(orn),
            physicsClientId=cid,
        )
        p.changeConstraint(self.cons, list(pos), list(orn), maxForce=200, physicsClientId=cid)
        self.nb = nb

    def move_grip(self, pos, orn):
        p.changeConstraint(self.cons, list(pos), list(orn), maxForce=200, physicsClientId=self.cid)

    def hoop_frames(self):
        out = [p.getBasePositionAndOrientation(self.body, physicsClientId=self.cid)]
        for s in p.getLinkStates(
            self.body, list(range(p.getNumJoints(self.body, physicsClientId=self.cid))), physicsClientId=self.cid
        ):
            out.append((s[4], s[5]))
        return out

    def nodes(self) -> np.ndarray:
        """Hoop-rim sample points (``boxes`` per hoop) — the ring method's 'nodes'."""
        out = []
        th = 2 * np.pi * np.arange(self.nb) / self.nb
        for pos, orn in self.hoop_frames():
            R = np.array(p.getMatrixFromQuaternion(orn)).reshape(3, 3)
            r = self.r_open  # rim radius (approximate for narrowed hoops)
            loc = np.stack([r * np.cos(th), r * np.sin(th), np.zeros_like(th)], axis=1)
            out.append(np.asarray(pos) + loc @ R.T)
        return np.concatenate(out)

    def ring(self) -> np.ndarray:
        return self.nodes()[: self.nb]

    def all_rings(self, x) -> list[np.ndarray]:
        return [x[k * self.nb : (k + 1) * self.nb] for k in range(len(x) // self.nb)]

    def bodies(self):
        return [self.body]


def contact_force(cid, sleeve, arm, scale=1.0) -> tuple[float, int]:
    """scale·Σ normal-force magnitude (index 9) and count of getContactPoints between sleeve and arm.

    For a soft body pass ``scale = numSubSteps``: the deformable world reports the normal force
    of the last sub-step's impulse over the full step (see the report).
    """
    cps = []
    for b in sleeve.bodies():
        cps += p.getContactPoints(bodyA=b, bodyB=arm, physicsClientId=cid)
    return scale * float(sum(abs(c[9]) for c in cps)), len(cps)


# ----------------------------------------------------------------------------- experiment


def run(args) -> dict:
    pts = arm_points(args.pose)
    path = GripperPath(pts, beyond=0.10, duration=args.move_s)
    cid = p.connect(p.DIRECT)
    if args.method == "softbody":
        p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD, physicsClientId=cid)
    p.setTimeStep(DT, physicsClientId=cid)
    if args.substeps:
        p.setPhysicsEngineParameter(numSubSteps=args.substeps, physicsClientId=cid)
    if args.method == "softbody" and args.sdf_voxel:
        p.setPhysicsEngineParameter(sparseSdfVoxelSize=args.sdf_voxel, physicsClientId=cid)
    arm = build_arm(pts, cid)
    pos0, orn0 = path.pose_at(0.0)
    if args.method == "softbody":
        verts, faces = garment.sleeve_mesh(args.length, args.radius, args.radius_end, args.rings, args.segments)
        obj = Path(tempfile.mkdtemp()) / "sleeve.obj"
        garment.write_obj(obj, verts, faces)
        sleeve = SoftSleeve(
            cid,
            obj,
            args.rings,
            args.segments,
            pos0,
            orn0,
            grip=args.grip,
            mass=args.mass,
            margin=args.margin,
            ks=args.ks,
            kd=args.kd,
            kb=args.kb,
            friction=args.friction,
            damp_all=args.damp_all,
            face_contact=args.face_contact,
        )
    else:
        sleeve = RingSleeve(
            cid,
            args.length,
            args.radius,
            args.radius_end,
            pos0,
            orn0,
            n_rings=args.n_hoops,
            mass=args.mass,
            friction=args.friction,
            joint_force=args.joint_force,
            overlap=args.overlap,
            boxes=args.boxes,
        )

    hist = dict(nan=False, max_dist=0.0, pen=-1.0, rings_in=0, best_progress=0.0, inside_final=False, forces=[], ncp=[])
    settle = args.settle
    t_step = 0.0
    n_steps = 0
    wall0 = time.perf_counter()
    for k in range(settle + args.steps):
        if k == 0:
            p.setGravity(0, 0, -9.81 / 2, physicsClientId=cid)
        if k == settle:
            p.setGravity(0, 0, -9.81, physicsClientId=cid)
        t = max(0, k - settle) * DT
        sleeve.move_grip(*path.pose_at(t))
        t0 = time.perf_counter()
        p.stepSimulation(physicsClientId=cid)
        t_step += time.perf_counter() - t0
        n_steps += 1
        if k % FRAME_SKIP == FRAME_SKIP - 1:  # per env step: the measurements a runtime would take
            x = sleeve.nodes()
            if not np.isfinite(x).all():
                hist["nan"] = True
                break
            hist["max_dist"] = max(hist["max_dist"], float(dist_to_arm(x, pts).max()))
            hist["pen"] = max(hist["pen"], penetration(x, pts))
            hist["rings_in"] = sum(ring_encloses_arm(r, pts) for r in sleeve.all_rings(x))
            ring = x[: len(sleeve.ring())] if args.method == "rings" else x[sleeve.opening]
            inside = ring_encloses_arm(ring, pts)
            if inside:
                hist["best_progress"] = max(hist["best_progress"], progress_along_arm(pts, ring.mean(axis=0)))
            hist["inside_final"] = inside
            f, n = contact_force(cid, sleeve, arm, scale=max(1, args.substeps) if args.method == "softbody" else 1.0)
            hist["forces"].append(f)
            hist["ncp"].append(n)
            if args.print and (k // FRAME_SKIP) % 25 == 24:
                c = ring.mean(axis=0)
                print(
                    f"  t={t:5.2f}s inside={int(inside)} progress={progress_along_arm(pts, c):.3f} "
                    f"lag={np.linalg.norm(c - path.pose_at(t)[0]):.3f} maxdist={dist_to_arm(x, pts).max():.2f} "
                    f"F={f:.3f}N ncp={n}"
                )
    wall = time.perf_counter() - wall0
    n_rings_total = len(sleeve.all_rings(sleeve.nodes()))
    p.disconnect(cid)
    L = arm_length(pts)
    return dict(
        nan=hist["nan"],
        max_dist=hist["max_dist"],
        pen=hist["pen"],
        rings_in=hist["rings_in"],
        n_rings=n_rings_total,
        inside_final=hist["inside_final"],
        progress=hist["best_progress"],
        arm_len=L,
        frac=hist["best_progress"] / L,
        force_median=float(np.median(hist["forces"])) if hist["forces"] else float("nan"),
        force_max=float(np.max(hist["forces"])) if hist["forces"] else float("nan"),
        ncp_max=int(max(hist["ncp"])) if hist["ncp"] else 0,
        phys_per_s=n_steps / t_step,
        phys_per_s_wall=n_steps / wall,
        env_per_s=n_steps / wall / FRAME_SKIP,
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--method", choices=["softbody", "rings"], default="softbody")
    ap.add_argument("--pose", choices=["straight", "bent"], default="straight")
    ap.add_argument("--steps", type=int, default=600, help="physics steps after settling (0.02 s each)")
    ap.add_argument("--settle", type=int, default=50, help="settle steps at g/2 before the motion")
    ap.add_argument("--move-s", type=float, default=10.0, help="seconds to move the opening hand→shoulder")
    ap.add_argument("--print", action="store_true", help="print progress every 25 env steps")
    ap.add_argument("--repeat", type=int, default=1, help="runs; speeds are reported as medians")
    ap.add_argument("--length", type=float, default=0.5)
    ap.add_argument("--radius", type=float, default=0.09)
    ap.add_argument("--radius-end", type=float, default=0.07)
    ap.add_argument("--substeps", type=int, default=None, help="numSubSteps (default 4 softbody, 0 rings)")
    ap.add_argument("--mass", type=float, default=0.1)
    # soft body
    ap.add_argument("--rings", type=int, default=11)
    ap.add_argument("--segments", type=int, default=12)
    ap.add_argument("--grip", choices=["ring", "pinch"], default="ring")
    ap.add_argument("--margin", type=float, default=SOFT_DEFAULTS["margin"])
    ap.add_argument("--ks", type=float, default=SOFT_DEFAULTS["ks"])
    ap.add_argument("--kd", type=float, default=SOFT_DEFAULTS["kd"])
    ap.add_argument("--kb", type=float, default=SOFT_DEFAULTS["kb"])
    ap.add_argument("--damp-all", type=int, default=SOFT_DEFAULTS["damp_all"])
    ap.add_argument("--friction", type=float, default=0.5)
    ap.add_argument("--face-contact", type=int, default=SOFT_DEFAULTS["face_contact"])
    ap.add_argument(
        "--sdf-voxel", type=float, default=SOFT_DEFAULTS["sdf_voxel"], help="sparseSdfVoxelSize (0: engine default)"
    )
    # rings
    ap.add_argument("--n-hoops", type=int, default=RING_DEFAULTS["n_rings"])
    ap.add_argument("--joint-force", type=float, default=RING_DEFAULTS["joint_force"])
    ap.add_argument("--overlap", type=float, default=RING_DEFAULTS["overlap"], help="hoop axial width / hoop spacing")
    ap.add_argument("--boxes", type=int, default=RING_DEFAULTS["boxes"], help="boxes per hoop")
    args = ap.parse_args(argv)
    if args.substeps is None:
        args.substeps = SOFT_DEFAULTS["substeps"] if args.method == "softbody" else 0

    results = []
    for i in range(args.repeat):
        r = run(args)
        results.append(r)
        print(
            f"run {i}: nan={r['nan']} max_node_dist_to_arm={r['max_dist']:.3f} m  arm_inside_opening_at_end={r['inside_final']}  "
            f"opening_progress={r['progress']:.3f}/{r['arm_len']:.3f} m ({100 * r['frac']:.0f}%)  "
            f"rings_around_arm_at_end={r['rings_in']}/{r['n_rings']}  max_penetration={1000 * r['pen']:.0f} mm  "
            f"contact_F median={r['force_median']:.3f} max={r['force_max']:.3f} N (max {r['ncp_max']} contacts)  "
            f"physics_steps/s={r['phys_per_s']:.0f} (incl. measurement {r['phys_per_s_wall']:.0f})  env_steps/s={r['env_per_s']:.0f}"
        )
    if args.repeat > 1:
        med = lambda k: statistics.median(r[k] for r in results)  # noqa: E731
        print(
            f"median of {args.repeat}: physics_steps/s={med('phys_per_s'):.0f} (with measurement {med('phys_per_s_wall'):.0f}), "
            f"env_steps/s={med('env_per_s'):.0f}, progress={med('progress'):.3f} m"
        )
    return results


if __name__ == "__main__":
    main()

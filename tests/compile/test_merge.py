"""`merge_fixed_links`: the seated person with its posture baked into fixed joints, merged down to
the head chain, checked against the unmerged body in real pybullet (DIRECT): joint count, mass,
every original link frame, whole-body COM and inertia, collision geometry (pose of every shape,
extents and ray casts), urdfdom's check_urdf, our lint, ``keep`` and byte-for-byte determinism.
Plus a small hand-computed case and the step-time comparison (printed; see ``-s``)."""

from __future__ import annotations

import math
import statistics
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pybullet as p
import pytest
import xacro

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run from a checkout without the package installed
    sys.path.insert(0, str(REPO))

from assistive_compiler.compile.lint import lint_urdf  # noqa: E402
from assistive_compiler.compile.merge import MergedFrame, merge_fixed_links  # noqa: E402
from assistive_compiler.person.body import body_measurements, format_fixed_joints  # noqa: E402
from assistive_compiler.person.skeleton import REVOLUTE_JOINTS  # noqa: E402

TEMPLATE = REPO / "templates" / "person" / "person.urdf.xacro"
HEAD_CHAIN = ("neck", "head_x", "head_y", "head_z")
# Seated posture: arms bent forward, thighs forward, knees bent; every other joint at 0.
POSTURE = {name: 0.0 for name in REVOLUTE_JOINTS if name not in HEAD_CHAIN}
POSTURE.update(
    right_elbow=-1.5708, left_elbow=-1.5708, right_hip_x=-1.5708, left_hip_x=-1.5708, right_knee=1.396, left_knee=1.396
)
# Where both bodies stand: the chest frame's world pose (tilted, so no frame is world-aligned).
BASE_POS = (0.3, -0.2, 1.1)
BASE_ORN = p.getQuaternionFromEuler((0.05, -0.1, 0.4))
HEAD_ANGLES = [(0.0, 0.0, 0.0, 0.0)] + [
    tuple(float(a) for a in np.random.default_rng(seed).uniform(-0.15, 0.15, 4)) for seed in (1, 2, 3)
]


def render() -> str:
    """The seated male; a fresh mappings dict each call (xacro mutates it)."""
    assert format_fixed_joints(POSTURE).count("=") == len(REVOLUTE_JOINTS) - len(HEAD_CHAIN)
    mappings = body_measurements("male").xacro_args(fixed_joints=dict(POSTURE))
    return xacro.process_file(str(TEMPLATE), mappings=mappings).toprettyxml(indent="  ")


@pytest.fixture(scope="module")
def person(tmp_path_factory):
    out = tmp_path_factory.mktemp("merge")
    original = render()
    merged, frames = merge_fixed_links(original)
    kept, kept_frames = merge_fixed_links(original, keep={"right_wrist"})
    paths = {}
    for name, text in (("original", original), ("merged", merged), ("kept", kept)):
        paths[name] = out / f"{name}.urdf"
        paths[name].write_text(text)
    return dict(original=original, merged=merged, frames=frames, kept=kept, kept_frames=kept_frames, paths=paths)


@pytest.fixture()
def client():
    cid = p.connect(p.DIRECT)
    yield cid
    p.disconnect(cid)


@pytest.fixture()
def two_clients():
    cids = (p.connect(p.DIRECT), p.connect(p.DIRECT))
    yield cids
    for cid in cids:
        p.disconnect(cid)


# --------------------------------------------------------------------------- helpers


def load(cid: int, path: Path, *, fixed: bool = True, flags: int = 0) -> int:
    return p.loadURDF(str(path), BASE_POS, BASE_ORN, useFixedBase=fixed, flags=flags, physicsClientId=cid)


def joints_by_name(cid: int, bid: int) -> dict[str, int]:
    return {
        p.getJointInfo(bid, i, physicsClientId=cid)[1].decode(): i
        for i in range(p.getNumJoints(bid, physicsClientId=cid))
    }


def set_head(cid: int, bid: int, angles) -> None:
    index = joints_by_name(cid, bid)
    for name, angle in zip(HEAD_CHAIN, angles):
        p.resetJointState(bid, index[name], angle, physicsClientId=cid)


def link_frames(cid: int, bid: int) -> dict[str, tuple]:
    """World pose of every URDF link frame (for the base: COM pose * inverse inertial frame)."""
    info = p.getDynamicsInfo(bid, -1, physicsClientId=cid)
    com = p.getBasePositionAndOrientation(bid, physicsClientId=cid)
    inv = p.invertTransform(info[3], info[4])
    frames = {p.getBodyInfo(bid, physicsClientId=cid)[0].decode(): p.multiplyTransforms(*com, *inv)}
    for i in range(p.getNumJoints(bid, physicsClientId=cid)):
        name = p.getJointInfo(bid, i, physicsClientId=cid)[12].decode()
        state = p.getLinkState(bid, i, computeForwardKinematics=True, physicsClientId=cid)
        frames[name] = (state[4], state[5])
    return frames


def angle_between(q1, q2) -> float:
    rel = p.getDifferenceQuaternion(q1, q2)
    return 2.0 * math.atan2(float(np.linalg.norm(rel[:3])), abs(rel[3]))


def rotation(q) -> np.ndarray:
    return np.array(p.getMatrixFromQuaternion(q)).reshape(3, 3)


def urdf_masses(xml: str) -> list[float]:
    return [float(m.get("value")) for m in ET.fromstring(xml).iter("mass")]


def rpy_matrix(rpy) -> np.ndarray:
    """URDF's roll-pitch-yaw, Rz(yaw) Ry(pitch) Rx(roll), in double precision (pybullet's
    multiplyTransforms and link states are single precision)."""
    r, pi_, y = rpy
    rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    ry = np.array([[math.cos(pi_), 0, math.sin(pi_)], [0, 1, 0], [-math.sin(pi_), 0, math.cos(pi_)]])
    rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    return rz @ ry @ rx


def origin_of(elem: ET.Element) -> np.ndarray:
    """4x4 transform of an element's <origin> (identity when absent)."""
    t = np.eye(4)
    origin = elem.find("origin")
    if origin is not None:
        t[:3, :3] = rpy_matrix([float(v) for v in origin.get("rpy", "0 0 0").split()])
        t[:3, 3] = [float(v) for v in origin.get("xyz", "0 0 0").split()]
    return t


def numpy_fk(xml: str, angles: dict[str, float]) -> dict[str, np.ndarray]:
    """4x4 pose of every link frame in the root link's frame (revolute joints at ``angles``)."""
    root = ET.fromstring(xml)
    joints = {j.find("child").get("link"): j for j in root.iter("joint")}
    frames: dict[str, np.ndarray] = {}

    def pose(link: str) -> np.ndarray:
        if link not in frames:
            joint = joints.get(link)
            if joint is None:
                frames[link] = np.eye(4)
            else:
                t = pose(joint.find("parent").get("link")) @ origin_of(joint)
                if joint.get("type") == "revolute":
                    axis = np.array([float(v) for v in joint.find("axis").get("xyz").split()])
                    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
                    q = angles[joint.get("name")]
                    spin = np.eye(4)
                    spin[:3, :3] = np.eye(3) + math.sin(q) * k + (1 - math.cos(q)) * (k @ k)
                    t = t @ spin
                frames[link] = t
        return frames[link]

    for link in root.iter("link"):
        pose(link.get("name"))
    return frames


def world_inertia_from_urdf(xml: str, frames: dict[str, np.ndarray]) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, COM and inertia about the origin of a URDF's <inertial> elements, placed with the
    given 4x4 link frames."""
    total, first, second = 0.0, np.zeros(3), np.zeros((3, 3))
    for link in ET.fromstring(xml).iter("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        t = frames[link.get("name")] @ origin_of(inertial)
        v = {k: float(inertial.find("inertia").get(k)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
        local = np.array(
            [[v["ixx"], v["ixy"], v["ixz"]], [v["ixy"], v["iyy"], v["iyz"]], [v["ixz"], v["iyz"], v["izz"]]]
        )
        r, c, m = t[:3, :3], t[:3, 3], float(inertial.find("mass").get("value"))
        total += m
        first += m * c
        second += r @ local @ r.T + m * (float(c @ c) * np.eye(3) - np.outer(c, c))
    return total, first / total, second


def world_inertia_from_pybullet(cid: int, bid: int) -> tuple[float, np.ndarray, np.ndarray]:
    """The same, from what pybullet made of the file (free base, URDF_USE_INERTIA_FROM_FILE):
    each link's mass, principal moments and world COM frame."""
    total, first, second = 0.0, np.zeros(3), np.zeros((3, 3))
    for i in range(-1, p.getNumJoints(bid, physicsClientId=cid)):
        info = p.getDynamicsInfo(bid, i, physicsClientId=cid)
        if i < 0:
            pos, orn = p.getBasePositionAndOrientation(bid, physicsClientId=cid)
        else:
            pos, orn = p.getLinkState(bid, i, computeForwardKinematics=True, physicsClientId=cid)[:2]
        r, c, m = rotation(orn), np.array(pos), info[0]
        total += m
        first += m * c
        second += r @ np.diag(info[2]) @ r.T + m * (float(c @ c) * np.eye(3) - np.outer(c, c))
    return total, first / total, second


def placed_shapes(xml: str, frames: dict[str, tuple], tag: str) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(geometry + material description, world position, world rotation) of every <tag>."""
    out = []
    for link in ET.fromstring(xml).iter("link"):
        for elem in link.findall(tag):
            origin = elem.find("origin")
            xyz = [float(v) for v in origin.get("xyz").split()]
            rpy = [float(v) for v in origin.get("rpy").split()]
            pos, orn = p.multiplyTransforms(*frames[link.get("name")], xyz, p.getQuaternionFromEuler(rpy))
            geom = elem.find("geometry")[0]
            material = elem.find("material")
            desc = f"{geom.tag}{sorted(geom.attrib.items())}"
            if material is not None:
                desc += ET.tostring(material, encoding="unicode").strip()
            out.append((desc, np.array(pos), rotation(orn)))
    return out


def cylinder_axis_free(desc: str, r1: np.ndarray, r2: np.ndarray) -> bool:
    """Equal shape orientation: a sphere's does not matter, the rest must match."""
    if desc.startswith("sphere"):
        return True
    return float(np.abs(r1 - r2).max()) < 1e-6


def support_aabb(cid: int, bid: int, gap: float = 0.05) -> np.ndarray:
    """Tight world AABB of the body's collision geometry, from pybullet's closest-point queries
    against six slabs just outside its (conservative) getAABB box. Rows: min, max."""
    n = p.getNumJoints(bid, physicsClientId=cid)
    boxes = [p.getAABB(bid, i, physicsClientId=cid) for i in range(-1, n)]
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    out = np.zeros((2, 3))
    for axis in range(3):
        half = np.full(3, 5.0)
        half[axis] = 0.5
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half.tolist(), physicsClientId=cid)
        for side, face in ((0, lo[axis] - gap), (1, hi[axis] + gap)):
            centre = 0.5 * (lo + hi)
            centre[axis] = face + (0.5 if side else -0.5)
            slab = p.createMultiBody(0, shape, basePosition=centre.tolist(), physicsClientId=cid)
            points = p.getClosestPoints(bid, slab, 1.0, physicsClientId=cid)
            d = min(pt[8] for pt in points)
            out[side, axis] = face - d if side else face + d
            p.removeBody(slab, physicsClientId=cid)
    return out


def ray_hits(cid: int, bid: int, starts, ends) -> tuple[np.ndarray, np.ndarray]:
    p.performCollisionDetection(physicsClientId=cid)
    results = p.rayTestBatch(starts.tolist(), ends.tolist(), physicsClientId=cid)
    hit = np.array([r[0] == bid for r in results])
    length = np.linalg.norm(ends - starts, axis=1)
    return hit, np.array([r[2] for r in results]) * length


# --------------------------------------------------------------------------- the person


def test_merged_person_has_only_the_head_chain_and_the_same_mass(person, client):
    merged = load(client, person["paths"]["merged"], fixed=False)
    infos = [
        p.getJointInfo(merged, i, physicsClientId=client) for i in range(p.getNumJoints(merged, physicsClientId=client))
    ]
    assert [info[1].decode() for info in infos] == list(HEAD_CHAIN)
    assert all(info[2] == p.JOINT_REVOLUTE for info in infos)
    assert p.getBodyInfo(merged, physicsClientId=client)[0].decode() == "chest"
    # 42 joints / 43 links before; 38 links merged (all but chest, neck, head_x/y links, head).
    frames = person["frames"]
    assert len(frames) == 38 and {f.into for f in frames.values()} == {"chest"}
    assert all(isinstance(f, MergedFrame) for f in frames.values())

    original = load(client, person["paths"]["original"], fixed=False)
    assert p.getNumJoints(original, physicsClientId=client) == 42

    def weigh(bid: int) -> float:
        return sum(
            p.getDynamicsInfo(bid, i, physicsClientId=client)[0]
            for i in range(-1, p.getNumJoints(bid, physicsClientId=client))
        )

    assert weigh(merged) == pytest.approx(weigh(original), rel=1e-9)
    assert sum(urdf_masses(person["merged"])) == pytest.approx(sum(urdf_masses(person["original"])), rel=1e-9)
    assert weigh(merged) == pytest.approx(78.4, rel=1e-9)


def test_every_original_link_frame_is_recovered(person, two_clients):
    c_orig, c_merged = two_clients
    original = load(c_orig, person["paths"]["original"])
    merged = load(c_merged, person["paths"]["merged"])
    frames = person["frames"]
    for angles in HEAD_ANGLES:
        set_head(c_orig, original, angles)
        set_head(c_merged, merged, angles)
        truth = link_frames(c_orig, original)
        surviving = link_frames(c_merged, merged)
        assert len(truth) == 43 and set(surviving) | set(frames) == set(truth)
        assert not set(surviving) & set(frames)
        for name, (pos, orn) in truth.items():
            if name in frames:
                f = frames[name]
                got = p.multiplyTransforms(*surviving[f.into], f.xyz, f.quat)
            else:
                got = surviving[name]
            assert np.allclose(got[0], pos, rtol=0, atol=1e-6), (name, angles)
            assert angle_between(got[1], orn) < 1e-6, (name, angles)
        assert np.allclose(surviving["chest"][0], BASE_POS, atol=1e-6)
        # The double-precision forward kinematics used for the inertia check agrees with pybullet.
        fk = numpy_fk(person["original"], dict(zip(HEAD_CHAIN, angles)))
        for name, (pos, orn) in truth.items():
            world = rotation(BASE_ORN) @ fk[name][:3, 3] + BASE_POS
            assert np.allclose(world, pos, rtol=0, atol=1e-6), name
            assert np.abs(rotation(BASE_ORN) @ fk[name][:3, :3] - rotation(orn)).max() < 1e-6, name


def test_whole_body_com_and_inertia_match(person, two_clients):
    # From the files' <inertial> elements with a double-precision forward kinematics of each
    # file (about the world origin of a tilted, offset base): equal to rounding.
    base = np.eye(4)
    base[:3, :3] = rotation(BASE_ORN)
    base[:3, 3] = BASE_POS
    for head in HEAD_ANGLES[:2]:
        angles = dict(zip(HEAD_CHAIN, head))
        m0, c0, i0 = world_inertia_from_urdf(
            person["original"], {k: base @ v for k, v in numpy_fk(person["original"], angles).items()}
        )
        m1, c1, i1 = world_inertia_from_urdf(
            person["merged"], {k: base @ v for k, v in numpy_fk(person["merged"], angles).items()}
        )
        assert m1 == pytest.approx(m0, rel=1e-9)
        assert np.allclose(c1, c0, rtol=0, atol=1e-9)
        assert np.allclose(i1, i0, rtol=0, atol=1e-9 * np.abs(i0).max())
    # The merged chest really carries off-diagonal inertia (the bent limbs), written unrotated.
    chest = next(link for link in ET.fromstring(person["merged"]).iter("link") if link.get("name") == "chest")
    assert chest.find("inertial/origin").get("rpy") == "0.0 0.0 0.0"
    assert float(chest.find("inertial/inertia").get("iyz")) != 0.0

    # From what pybullet built: free base (a fixed base weighs 0), inertia from the file as the
    # runtime loads it (pybullet diagonalises each tensor into a rotated inertial frame), COM
    # frames from getLinkState (double precision, unlike its URDF-frame outputs).
    c_orig, c_merged = two_clients
    flags = p.URDF_USE_INERTIA_FROM_FILE
    original = load(c_orig, person["paths"]["original"], fixed=False, flags=flags)
    merged = load(c_merged, person["paths"]["merged"], fixed=False, flags=flags)
    set_head(c_orig, original, HEAD_ANGLES[1])
    set_head(c_merged, merged, HEAD_ANGLES[1])
    m2, c2, i2 = world_inertia_from_pybullet(c_orig, original)
    m3, c3, i3 = world_inertia_from_pybullet(c_merged, merged)
    assert m3 == pytest.approx(m2, rel=1e-9) and m2 == pytest.approx(m0, rel=1e-9)
    assert np.allclose(c3, c2, rtol=0, atol=1e-9) and np.allclose(c2, c0, rtol=0, atol=1e-9)
    assert np.allclose(i3, i2, rtol=0, atol=1e-9 * np.abs(i2).max())
    assert np.allclose(i2, i0, rtol=0, atol=1e-9 * np.abs(i0).max())


def test_collision_geometry_is_equivalent(person, two_clients):
    c_orig, c_merged = two_clients
    original = load(c_orig, person["paths"]["original"])
    merged = load(c_merged, person["paths"]["merged"])
    set_head(c_orig, original, HEAD_ANGLES[2])
    set_head(c_merged, merged, HEAD_ANGLES[2])

    # Every visual and collision element sits where it did, with the same geometry and material.
    for tag in ("collision", "visual"):
        before = placed_shapes(person["original"], link_frames(c_orig, original), tag)
        after = placed_shapes(person["merged"], link_frames(c_merged, merged), tag)
        assert len(after) == len(before) > 0
        unused = list(after)
        for desc, pos, rot in before:
            match = next(
                (
                    s
                    for s in unused
                    if s[0] == desc and np.abs(s[1] - pos).max() < 1e-6 and cylinder_axis_free(desc, s[2], rot)
                ),
                None,
            )
            assert match is not None, (tag, desc, pos)
            unused.remove(match)

    # Extents of the geometry itself (pybullet's getAABB is a conservative box that depends on
    # how shapes are grouped into links, so it is not compared directly).
    box0 = support_aabb(c_orig, original)
    box1 = support_aabb(c_merged, merged)
    assert np.allclose(box1, box0, rtol=0, atol=1e-4), (box0, box1)

    # 200 seeded rays through the box: same hit / miss, same distance.
    rng = np.random.default_rng(7)
    targets = box0[0] + rng.uniform(0.0, 1.0, (200, 3)) * (box0[1] - box0[0])
    dirs = rng.normal(size=(200, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    reach = 2.0 * float(np.linalg.norm(box0[1] - box0[0]))
    starts, ends = targets - reach * dirs, targets + reach * dirs
    hit0, dist0 = ray_hits(c_orig, original, starts, ends)
    hit1, dist1 = ray_hits(c_merged, merged, starts, ends)
    assert hit0.sum() >= 50  # the test means something
    assert (hit1 == hit0).all()
    assert np.abs(dist1[hit0] - dist0[hit0]).max() < 1e-4


def test_merged_urdf_passes_check_urdf_and_lint(person):
    assert lint_urdf(person["merged"], template="merged") == []
    assert lint_urdf(person["kept"], template="merged") == []
    exe = Path(sys.executable).parent / "check_urdf"
    if not exe.is_file():
        pytest.skip("check_urdf (cmeel-urdfdom) not installed next to the interpreter")
    for name in ("merged", "kept"):
        res = subprocess.run([str(exe), str(person["paths"][name])], capture_output=True, text=True, timeout=30)
        assert res.returncode == 0, res.stdout + res.stderr
        assert "Successfully Parsed XML" in res.stdout
        assert "error" not in (res.stdout + res.stderr).lower()


def test_keep_leaves_a_link_on_its_fixed_joint(person, two_clients):
    frames = person["kept_frames"]
    assert "right_wrist" not in frames
    assert set(frames) == set(person["frames"]) - {"right_wrist"}
    c_orig, c_kept = two_clients
    original = load(c_orig, person["paths"]["original"])
    kept = load(c_kept, person["paths"]["kept"])
    infos = [
        p.getJointInfo(kept, i, physicsClientId=c_kept) for i in range(p.getNumJoints(kept, physicsClientId=c_kept))
    ]
    assert len(infos) == 5
    wrist = next(info for info in infos if info[12].decode() == "right_wrist")
    assert wrist[1].decode() == "right_wrist_y" and wrist[2] == p.JOINT_FIXED
    assert wrist[16] == -1  # re-parented onto the chest (the base)
    assert p.getCollisionShapeData(kept, wrist[0], physicsClientId=c_kept)  # the hand is on it
    truth = link_frames(c_orig, original)
    got = link_frames(c_kept, kept)
    assert np.allclose(got["right_wrist"][0], truth["right_wrist"][0], atol=1e-6)
    assert angle_between(got["right_wrist"][1], truth["right_wrist"][1]) < 1e-6
    f = frames["right_wrist_x_link"]
    pos, _ = p.multiplyTransforms(*got[f.into], f.xyz, f.quat)
    assert np.allclose(pos, truth["right_wrist_x_link"][0], atol=1e-6)


def test_merge_is_deterministic(person):
    again, frames = merge_fixed_links(render())
    assert again == person["merged"] and frames == person["frames"]
    assert list(frames) == list(person["frames"])
    assert merge_fixed_links(person["original"])[0].encode() == person["merged"].encode()
    # Nothing left to merge: the document comes back byte for byte.
    assert merge_fixed_links(person["merged"]) == (person["merged"], {})


# --------------------------------------------------------------------------- by hand

SMALL = """<?xml version="1.0"?>
<robot name="small">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base">
    <inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="2"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/></inertial>
    <collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry><box size="1 1 1"/></geometry></collision>
  </link>
  <joint name="fix" type="fixed"><parent link="base"/><child link="arm"/>
    <origin xyz="1 0 0" rpy="0 0 1.5707963267948966"/></joint>
  <link name="arm">
    <inertial><origin xyz="0 0 0" rpy="0 1.5707963267948966 0"/><mass value="2"/>
      <inertia ixx="4" ixy="0" ixz="0" iyy="5" iyz="0" izz="6"/></inertial>
    <visual><origin xyz="0.5 0 0" rpy="0 0 0"/><geometry><sphere radius="0.1"/></geometry>
      <material name="red"/></visual>
  </link>
  <joint name="spin" type="revolute"><parent link="arm"/><child link="tip"/>
    <origin xyz="0 1 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="tip">
    <inertial><origin xyz="0 0 0" rpy="0 0 0"/><mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
  </link>
</robot>
"""


def test_small_merge_by_hand():
    out, frames = merge_fixed_links(SMALL)
    root = ET.fromstring(out)
    assert [link.get("name") for link in root.iter("link")] == ["base", "tip"]
    assert frames == {
        "arm": MergedFrame("base", (1.0, 0.0, 0.0), (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)))
    }
    base = root.find("link")
    # arm's tensor: Ry(90deg) swaps x and z -> diag(6, 5, 4); Rz(90deg) swaps x and y ->
    # diag(5, 6, 4). COM at (0.5, 0, 0); each 2 kg mass 0.5 m off along x adds 0.5 to iyy, izz.
    inertial = base.find("inertial")
    assert inertial.find("origin").attrib == {"xyz": "0.5 0.0 0.0", "rpy": "0.0 0.0 0.0"}
    assert inertial.find("mass").get("value") == "4.0"
    tensor = {k: float(v) for k, v in inertial.find("inertia").attrib.items()}
    assert tensor == {"ixx": 6.0, "ixy": 0.0, "ixz": 0.0, "iyy": 9.0, "iyz": 0.0, "izz": 8.0}
    # The sphere (and its material) moves onto base: (1, 0, 0) + Rz(90deg)(0.5, 0, 0).
    visual = base.find("visual")
    assert visual.find("origin").get("xyz") == "1.0 0.5 0.0"
    assert visual.find("material").get("name") == "red"
    assert [e.tag for e in base] == ["inertial", "collision", "visual"]
    # The revolute joint now hangs from base: (1, 0, 0) + Rz(90deg)(0, 1, 0) = (0, 0, 0).
    spin = root.find("joint")
    assert spin.find("parent").get("link") == "base" and spin.find("axis").get("xyz") == "0 0 1"
    assert spin.find("origin").get("xyz") == "0.0 0.0 0.0"
    rpy = [float(v) for v in spin.find("origin").get("rpy").split()]
    assert rpy == pytest.approx([0.0, 0.0, math.pi / 2], rel=1e-11)  # 12 significant digits
    assert lint_urdf(out, template="small") == []
    # Unknown keep names are refused; keeping arm changes nothing.
    with pytest.raises(ValueError, match="armm"):
        merge_fixed_links(SMALL, keep=["armm"])
    kept, none = merge_fixed_links(SMALL, keep=["arm"])
    assert none == {} and [link.get("name") for link in ET.fromstring(kept).iter("link")] == ["base", "arm", "tip"]


# --------------------------------------------------------------------------- step time


def test_step_time_original_vs_merged(person):
    """Fixed base, gravity, head joints position-controlled, loaded as the runtime loads bodies
    (URDF_USE_INERTIA_FROM_FILE): median over 5 runs of the time of 300 steps after 20 warm-up
    steps. Printed (pytest -s); merged must not be slower."""

    def one_run(path: Path) -> float:
        cid = p.connect(p.DIRECT)
        try:
            p.setGravity(0, 0, -9.81, physicsClientId=cid)
            bid = load(cid, path, flags=p.URDF_USE_INERTIA_FROM_FILE)
            index = joints_by_name(cid, bid)
            p.setJointMotorControlArray(
                bid,
                [index[j] for j in HEAD_CHAIN],
                p.POSITION_CONTROL,
                targetPositions=[0.1, -0.2, 0.15, 0.3],
                forces=[40, 30, 30, 20],
                physicsClientId=cid,
            )
            for _ in range(20):
                p.stepSimulation(physicsClientId=cid)
            start = time.perf_counter()
            for _ in range(300):
                p.stepSimulation(physicsClientId=cid)
            return time.perf_counter() - start
        finally:
            p.disconnect(cid)

    times: dict[str, list[float]] = {"original": [], "merged": []}
    for _ in range(5):
        for name in times:  # interleaved, so drift hits both alike
            times[name].append(one_run(person["paths"][name]))
    med = {name: statistics.median(ts) for name, ts in times.items()}
    print(
        f"\nstepSimulation x300 (median of 5): original (43 links) {med['original'] * 1e3:.2f} ms "
        f"= {med['original'] / 300 * 1e6:.1f} us/step; merged (5 links) {med['merged'] * 1e3:.2f} ms "
        f"= {med['merged'] / 300 * 1e6:.1f} us/step; speed-up x{med['original'] / med['merged']:.2f}"
    )
    assert med["merged"] < med["original"]

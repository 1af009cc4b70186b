"""Feeding-scene templates (Jaco, wheelchair, table, bowl, spoon): every one renders with its
defaults, passes check_urdf, loads in PyBullet with no warnings and in yourdfpy, follows the
template conventions, and has the sizes, frames and physics the task relies on.
Real xacro, PyBullet and check_urdf; no mocks."""

from __future__ import annotations

import math
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
import xacro
import yourdfpy

from assistive_compiler.compile.external_checks import captured_c_output

TEMPLATES = Path(__file__).resolve().parents[2] / "templates"
CHECK_URDF = Path(sys.executable).parent / "check_urdf"
PI = math.pi

JACO = "robots/jaco.urdf.xacro"
WHEELCHAIR = "furniture/wheelchair.urdf.xacro"
TABLE = "furniture/table.urdf.xacro"
BOWL = "furniture/bowl.urdf.xacro"
SPOON = "tools/spoon.urdf.xacro"

CASES = [
    (JACO, {}),
    (WHEELCHAIR, {}),
    (WHEELCHAIR, {"robot_mount": "right"}),
    (WHEELCHAIR, {"robot_mount": "left"}),
    (TABLE, {}),
    (BOWL, {}),
    (SPOON, {}),
]
CASE_IDS = ["jaco", "wheelchair", "wheelchair-right", "wheelchair-left", "table", "bowl", "spoon"]

# The reference's particle grid relative to the spoon base (feeding task).
PARTICLE_RADIUS = 0.005
PARTICLE_MASS = 0.001
PARTICLE_GRID = [(i * 0.01 - 0.005, j * 0.01, k * 0.01 + 0.01) for i in range(2) for j in range(2) for k in range(2)]


# --------------------------------------------------------------------------------------------
# helpers


def render(template: str, out_dir: Path, **args) -> Path:
    mappings = {k: str(v) for k, v in args.items()}
    text = xacro.process_file(str(TEMPLATES / template), mappings=mappings).toprettyxml(indent="  ")
    stem = Path(template).name.replace(".urdf.xacro", "")
    suffix = "".join(f"_{k}-{v}" for k, v in sorted(mappings.items()))
    path = out_dir / f"{stem}{suffix}.urdf"
    path.write_text(text)
    return path


def load_quiet(cid: int, path: Path, pos=(0, 0, 0), orn=(0, 0, 0, 1), fixed=True, flags=0):
    """Load a URDF and return (body, printed text)."""
    with captured_c_output() as out:
        body = pb.loadURDF(str(path), list(pos), list(orn), useFixedBase=fixed, flags=flags, physicsClientId=cid)
    return body, out[0]


def link_index(cid: int, body: int, name: str) -> int:
    for j in range(pb.getNumJoints(body, physicsClientId=cid)):
        if pb.getJointInfo(body, j, physicsClientId=cid)[12].decode() == name:
            return j
    raise KeyError(name)


def link_frame(cid: int, body: int, name: str):
    ls = pb.getLinkState(body, link_index(cid, body, name), computeForwardKinematics=True, physicsClientId=cid)
    return np.array(ls[4]), np.array(ls[5])


def ray_hit(cid: int, start, end):
    # PyBullet's broadphase AABB of a body whose inertial frame is offset from its link frame is
    # stale right after loadURDF; a collision pass refreshes it before ray casting.
    pb.performCollisionDetection(physicsClientId=cid)
    hit = pb.rayTest(list(start), list(end), physicsClientId=cid)[0]
    assert hit[0] >= 0, f"ray {start} -> {end} hit nothing"
    return np.array(hit[3])


def probe_clear(cid: int, body: int, centre, half_extents) -> float:
    """Smallest distance between a box probe and the body (positive = clear)."""
    shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=list(half_extents), physicsClientId=cid)
    probe = pb.createMultiBody(0, shape, -1, list(centre), physicsClientId=cid)
    pts = pb.getClosestPoints(probe, body, 0.05, physicsClientId=cid)
    pb.removeBody(probe, physicsClientId=cid)
    return min((p[8] for p in pts), default=0.05)


def total_mass(model: yourdfpy.URDF) -> float:
    return sum(link.inertial.mass for link in model.robot.links)


def assert_links_physical(root) -> None:
    """Every link of a URDF tree: positive mass, a physically valid inertia (positive eigenvalues
    obeying the triangle inequality), primitive collision and visual shapes only."""
    for link in root.iter("link"):
        inertial = link.find("inertial")
        assert inertial is not None, link.get("name")
        assert float(inertial.find("mass").get("value")) > 0
        i = {k: float(v) for k, v in inertial.find("inertia").attrib.items()}
        tensor = np.array(
            [[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]]
        )
        ev = np.linalg.eigvalsh(tensor)
        assert ev.min() > 0, link.get("name")
        assert ev[0] + ev[1] >= ev[2] * (1 - 1e-9), link.get("name")  # triangle inequality
        for geom in link.iter("geometry"):
            kinds = [child.tag for child in geom]
            assert kinds and set(kinds) <= {"box", "cylinder", "sphere"}, kinds


@pytest.fixture(scope="module")
def out_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("scene_templates")


# --------------------------------------------------------------------------------------------
# every template


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_check_urdf_passes(template, args, out_dir):
    path = render(template, out_dir, **args)
    res = subprocess.run([str(CHECK_URDF), str(path)], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Successfully Parsed XML" in res.stdout


def test_warning_capture_works(cid, tmp_path):
    """Positive control: a link without <inertial> makes PyBullet print a warning."""
    bad = tmp_path / "bad.urdf"
    bad.write_text(
        '<robot name="bad"><link name="a"><visual><geometry><box size="1 1 1"/></geometry></visual></link></robot>'
    )
    _, text = load_quiet(cid, bad)
    assert "warning" in text.lower()


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_pybullet_loads_without_warnings(template, args, out_dir, cid):
    path = render(template, out_dir, **args)
    body, text = load_quiet(cid, path)
    assert body >= 0
    assert "warning" not in text.lower(), text
    assert "error" not in text.lower(), text


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_yourdfpy_loads(template, args, out_dir):
    path = render(template, out_dir, **args)
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    assert model.validate()
    assert len(model.robot.links) >= 1


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_conventions(template, args, out_dir):
    """Positive masses, physically valid inertias, ordered limits with effort and velocity on
    movable joints, unit axes, primitives only."""
    root = ET.parse(render(template, out_dir, **args)).getroot()
    assert_links_physical(root)
    for joint in root.iter("joint"):
        if joint.get("type") in ("revolute", "prismatic"):
            lim = joint.find("limit")
            assert float(lim.get("lower")) < float(lim.get("upper"))
            assert float(lim.get("effort")) > 0 and float(lim.get("velocity")) > 0
        if joint.get("type") != "fixed":
            axis = np.array([float(v) for v in joint.find("axis").get("xyz").split()])
            assert np.linalg.norm(axis) == pytest.approx(1.0)
            assert np.count_nonzero(axis) == 1


# --------------------------------------------------------------------------------------------
# Jaco


def test_jaco_names_and_mass(out_dir):
    model = yourdfpy.URDF.load(str(render(JACO, out_dir)), build_scene_graph=True, load_meshes=False)
    assert model.base_link == "j2s7s300_link_base"
    expected = {f"j2s7s300_joint_{i}" for i in range(1, 8)} | {"j2s7s300_joint_end_effector"}
    expected |= {f"j2s7s300_joint_finger_{i}" for i in (1, 2, 3)}
    expected |= {f"j2s7s300_joint_finger_tip_{i}" for i in (1, 2, 3)}
    assert set(model.joint_map) == expected
    assert 5.2 <= total_mass(model) <= 5.4


# --------------------------------------------------------------------------------------------
# wheelchair


def test_wheelchair_without_mount_has_no_mount_link(out_dir):
    model = yourdfpy.URDF.load(str(render(WHEELCHAIR, out_dir)), build_scene_graph=True, load_meshes=False)
    assert sorted(link.name for link in model.robot.links) == ["seat", "wheelchair"]
    assert total_mass(model) > 0
    # The seat frame: on the cushion top, below the reference's chest position (0, 0.03).
    np.testing.assert_allclose(model.get_transform("seat", "wheelchair")[:3, 3], [0, 0.03, 0.43])


def test_wheelchair_rejects_unknown_mount(out_dir):
    with pytest.raises(xacro.XacroException, match="middle"):
        render(WHEELCHAIR, out_dir, robot_mount="middle")


@pytest.mark.parametrize("side,x,yaw", [("right", -0.35, -PI / 2), ("left", 0.35, PI / 2)])
def test_wheelchair_mount_frame(side, x, yaw, out_dir, cid):
    path = render(WHEELCHAIR, out_dir, robot_mount=side)
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    expected = np.eye(4)
    expected[:3, :3] = [[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]]
    expected[:3, 3] = [x, -0.3, 0.3]
    np.testing.assert_allclose(model.get_transform("robot_mount", "wheelchair"), expected, atol=1e-9)
    # The same in PyBullet, with the chair where the task puts it: world (0, 0, 0.06).
    chair, _ = load_quiet(cid, path, pos=(0, 0, 0.06))
    pos, orn = link_frame(cid, chair, "robot_mount")
    np.testing.assert_allclose(pos, [x, -0.3, 0.36], atol=1e-6)
    np.testing.assert_allclose(pb.getEulerFromQuaternion(orn.tolist()), [0, 0, yaw], atol=1e-6)
    # A Jaco on that frame does not touch the chair (post, bar, wheels) at its base.
    jaco, _ = load_quiet(cid, render(JACO, out_dir), pos=pos, orn=orn)
    pts = pb.getClosestPoints(jaco, chair, 0.05, linkIndexA=-1, physicsClientId=cid)
    assert min((p[8] for p in pts), default=0.05) > 0.0


def test_wheelchair_dimensions_and_surfaces(out_dir, cid):
    """Chair at world (0, 0, 0.06) as in the task; checks in world coordinates."""
    chair, _ = load_quiet(cid, render(WHEELCHAIR, out_dir), pos=(0, 0, 0.06))
    lo, hi = (np.array(v) for v in pb.getAABB(chair, -1, physicsClientId=cid))
    size = hi - lo
    assert size[0] == pytest.approx(0.78, abs=0.03)
    assert size[1] == pytest.approx(0.95, abs=0.03)
    assert size[2] == pytest.approx(1.24, abs=0.03)
    assert lo[2] == pytest.approx(0.0, abs=0.005)  # wheels stand on the floor
    # Seat cushion top ~0.49, over x +-0.25 and y -0.25..0.2.
    for x, y in [(0, -0.02), (0.22, -0.22), (-0.22, 0.15)]:
        assert ray_hit(cid, (x, y, 2.0), (x, y, 0.0))[2] == pytest.approx(0.49, abs=0.005)
    # Backrest front face ~ y 0.17, reaching up to ~1.2.
    assert ray_hit(cid, (0, -0.2, 0.9), (0, 1.0, 0.9))[1] == pytest.approx(0.17, abs=0.005)
    assert ray_hit(cid, (0, 0.2, 2.0), (0, 0.2, 0.0))[2] == pytest.approx(1.2, abs=0.02)
    # Armrests at x +-0.3, top ~0.70.
    for x in (-0.3, 0.3):
        assert ray_hit(cid, (x, -0.02, 2.0), (x, -0.02, 0.0))[2] == pytest.approx(0.70, abs=0.005)
    # Room for the seated person: torso/hips above the seat, thighs forward, shins and feet.
    assert probe_clear(cid, chair, (0, -0.02, 0.83), (0.2, 0.17, 0.33)) > 0
    assert probe_clear(cid, chair, (0, -0.35, 0.58), (0.18, 0.15, 0.08)) > 0
    assert probe_clear(cid, chair, (0, -0.45, 0.30), (0.17, 0.1, 0.22)) > 0


# --------------------------------------------------------------------------------------------
# table


def test_table_top_and_args(out_dir, cid):
    table, _ = load_quiet(cid, render(TABLE, out_dir))
    lo, hi = (np.array(v) for v in pb.getAABB(table, -1, physicsClientId=cid))
    np.testing.assert_allclose(lo, [-0.75, -0.5, 0.0], atol=0.003)
    np.testing.assert_allclose(hi, [0.75, 0.5, 0.725], atol=0.003)
    for x, y in [(0, 0), (0.7, 0.45), (-0.7, -0.45)]:
        assert ray_hit(cid, (x, y, 2.0), (x, y, 0.0))[2] == pytest.approx(0.725, abs=1e-3)
    # Underside of the top at 0.675 (top 0.05 thick, centred at 0.70).
    assert ray_hit(cid, (0, 0, 0.3), (0, 0, 2.0))[2] == pytest.approx(0.675, abs=1e-3)
    # Legs (0.08 square, centres 0.1 m in from the edges) under the corners.
    for sx, sy in [(1, 1), (1, -1), (-1, 1), (-1, -1)]:
        hit = ray_hit(cid, (sx * 1.0, sy * 0.4, 0.3), (0, sy * 0.4, 0.3))
        assert hit[0] == pytest.approx(sx * 0.69, abs=2e-3)
    # Args resize it.
    small, _ = load_quiet(cid, render(TABLE, out_dir, top_height_m=0.6, width_m=1.0, depth_m=0.8), pos=(5, 0, 0))
    lo, hi = (np.array(v) for v in pb.getAABB(small, -1, physicsClientId=cid))
    np.testing.assert_allclose(hi - lo, [1.0, 0.8, 0.6], atol=0.005)


# --------------------------------------------------------------------------------------------
# bowl


def test_bowl_size_mass_segments(out_dir, cid):
    path = render(BOWL, out_dir)
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    assert total_mass(model) == pytest.approx(0.1)
    assert len(model.link_map["bowl"].collisions) == 1 + 16
    bowl, _ = load_quiet(cid, path)
    lo, hi = (np.array(v) for v in pb.getAABB(bowl, -1, physicsClientId=cid))
    assert hi[0] - lo[0] == pytest.approx(0.144, abs=0.005)
    assert hi[1] - lo[1] == pytest.approx(0.144, abs=0.005)
    assert hi[2] == pytest.approx(0.06, abs=0.003)
    # Open on top: a ray down the middle reaches the base disc, not a lid.
    assert ray_hit(cid, (0, 0, 1.0), (0, 0, -1.0))[2] == pytest.approx(0.01, abs=2e-3)
    # The ring is closed: horizontal rays from the centre hit a wall in every direction.
    for k in range(32):
        a = 2 * PI * k / 32
        hit = ray_hit(cid, (0, 0, 0.04), (0.2 * math.cos(a), 0.2 * math.sin(a), 0.04))
        assert 0.05 < math.hypot(hit[0], hit[1]) < 0.072
    n8 = yourdfpy.URDF.load(str(render(BOWL, out_dir, segments=8)), build_scene_graph=True, load_meshes=False)
    assert len(n8.link_map["bowl"].collisions) == 1 + 8


def test_bowl_holds_things(out_dir, cid):
    pb.setGravity(0, 0, -9.81, physicsClientId=cid)
    pb.setTimeStep(0.02, physicsClientId=cid)
    ground = pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=cid)
    pb.createMultiBody(0, ground, physicsClientId=cid)
    bowl, _ = load_quiet(cid, render(BOWL, out_dir), fixed=False)
    ball = pb.createCollisionShape(pb.GEOM_SPHERE, radius=0.01, physicsClientId=cid)
    starts = [(0, 0), (0.03, 0), (-0.03, 0.02), (0.0, -0.045), (0.045, 0.03)]
    balls = [pb.createMultiBody(0.005, ball, -1, [x, y, 0.025], physicsClientId=cid) for x, y in starts]
    for _ in range(50):
        pb.stepSimulation(physicsClientId=cid)
    pos, orn = pb.getBasePositionAndOrientation(bowl, physicsClientId=cid)
    assert abs(pb.getEulerFromQuaternion(orn)[0]) < 0.05
    assert abs(pb.getEulerFromQuaternion(orn)[1]) < 0.05
    for b in balls:
        p = np.array(pb.getBasePositionAndOrientation(b, physicsClientId=cid)[0])
        assert math.hypot(p[0] - pos[0], p[1] - pos[1]) < 0.07
        assert 0.015 < p[2] < 0.06


# --------------------------------------------------------------------------------------------
# spoon


def test_spoon_frames_and_mass(out_dir, cid):
    path = render(SPOON, out_dir)
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    assert model.base_link == "spoon"
    assert model.link_map["spoon"].inertial.mass == pytest.approx(1.0)
    np.testing.assert_allclose(model.link_map["spoon"].inertial.origin, np.eye(4))
    np.testing.assert_allclose(model.get_transform("spoon_tip", "spoon")[:3, 3], [0, 0.005, 0])
    end = model.get_transform("spoon_handle_end", "spoon")[:3, 3]
    assert end[0] == pytest.approx(0.0)
    assert -0.16 < end[1] < -0.13  # ~0.13 m handle behind the tray
    assert 0.0 < end[2] < 0.04  # slightly raised
    heavy = yourdfpy.URDF.load(str(render(SPOON, out_dir, mass_kg=0.25)), build_scene_graph=True, load_meshes=False)
    assert heavy.link_map["spoon"].inertial.mass == pytest.approx(0.25)
    spoon, _ = load_quiet(cid, path)
    # Floor top at z = 0 inside the tray; tray open upwards.
    for x, y in [(0, 0.005), (-0.015, -0.01), (0.015, 0.02)]:
        assert ray_hit(cid, (x, y, 0.5), (x, y, -0.5))[2] == pytest.approx(0.0, abs=1e-3)
    # Walls around the interior x [-0.017, 0.017], y [-0.012, 0.022], rising to ~0.012.
    assert ray_hit(cid, (0, 0.005, 0.006), (0.2, 0.005, 0.006))[0] == pytest.approx(0.0199, abs=0.002)
    assert ray_hit(cid, (0, 0.005, 0.006), (-0.2, 0.005, 0.006))[0] == pytest.approx(-0.0199, abs=0.002)
    assert ray_hit(cid, (0, 0.005, 0.006), (0, 0.2, 0.006))[1] == pytest.approx(0.0249, abs=0.002)
    assert ray_hit(cid, (0, 0.005, 0.006), (0, -0.2, 0.006))[1] == pytest.approx(-0.0149, abs=0.002)
    # The tray is closed all round (corners included) up to near the rim.
    for z in (0.001, 0.006, 0.011):
        for k in range(36):
            a = 2 * PI * k / 36
            ray_hit(cid, (0, 0.005, z), (0.2 * math.cos(a), 0.005 + 0.2 * math.sin(a), z))
    # Just inside the rim (x 0.024) a ray from above lands on the flared wall's top edge.
    assert ray_hit(cid, (0.024, 0.005, 0.5), (0.024, 0.005, -0.5))[2] == pytest.approx(0.012, abs=0.002)


def _in_tray(cid, spoon, balls) -> np.ndarray:
    pos, orn = pb.getBasePositionAndOrientation(spoon, physicsClientId=cid)
    inv = pb.invertTransform(pos, orn)
    local = np.array(
        [
            pb.multiplyTransforms(*inv, pb.getBasePositionAndOrientation(b, physicsClientId=cid)[0], [0, 0, 0, 1])[0]
            for b in balls
        ]
    )
    return (
        (np.abs(local[:, 0]) < 0.03)
        & (local[:, 1] > -0.02)
        & (local[:, 1] < 0.035)
        & (local[:, 2] > -0.001)
        & (local[:, 2] < 0.03)
    )


@pytest.mark.parametrize("sub_steps", [1, 4])
@pytest.mark.parametrize(
    "tilt_rpy", [(0, PI / 2, 0), (PI / 2, 0, 0), (-PI / 2, 0, 0)], ids=["roll-sideways", "tip-up", "tip-down"]
)
def test_spoon_holds_food_then_spills_when_tilted(out_dir, cid, sub_steps, tilt_rpy):
    """The reference's 8 particles, dropped on the grid above a level spoon at z 1.0, stay in
    the tray for 1 s (time step 0.02 s as in the reference, with and without sub-steps);
    turning the spoon 90 degrees spills most of them within 1 s."""
    pb.setGravity(0, 0, -9.81, physicsClientId=cid)
    pb.setTimeStep(0.02, physicsClientId=cid)
    pb.setPhysicsEngineParameter(numSubSteps=sub_steps, physicsClientId=cid)
    spoon, _ = load_quiet(cid, render(SPOON, out_dir), pos=(0, 0, 1.0))
    shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=PARTICLE_RADIUS, physicsClientId=cid)
    balls = [
        pb.createMultiBody(PARTICLE_MASS, shape, -1, [x, y, 1.0 + z], physicsClientId=cid) for x, y, z in PARTICLE_GRID
    ]
    for _ in range(50):
        pb.stepSimulation(physicsClientId=cid)
    assert _in_tray(cid, spoon, balls).all()
    pb.resetBasePositionAndOrientation(spoon, [0, 0, 1.0], pb.getQuaternionFromEuler(tilt_rpy), physicsClientId=cid)
    for _ in range(50):
        pb.stepSimulation(physicsClientId=cid)
    assert _in_tray(cid, spoon, balls).sum() <= 2

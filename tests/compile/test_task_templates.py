"""Tool and furniture templates of the other five tasks (scratcher, wiper, cup, scooper, bed):
every one renders with its defaults, passes check_urdf and the compiler's lint, loads in PyBullet
with no warnings and in yourdfpy, follows the template conventions, and has the sizes, frames,
masses and physics its task relies on; every robot holds every new tool in its fingers without
its hand cutting into the tool. Real xacro, PyBullet, yourdfpy and check_urdf; no mocks."""

from __future__ import annotations

import math
import subprocess
import xml.etree.ElementTree as ET
from functools import cache
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
import xacro
import yourdfpy
from test_scene_templates import CHECK_URDF, PI, TEMPLATES, assert_links_physical, load_quiet

from assistive_compiler.compile.lint import lint_urdf
from assistive_compiler.library import Library

SCRATCHER = "tools/scratcher.urdf.xacro"
WIPER = "tools/wiper.urdf.xacro"
CUP = "tools/cup.urdf.xacro"
SCOOPER = "tools/scooper.urdf.xacro"
BED = "furniture/bed.urdf.xacro"

CASES = [
    (SCRATCHER, {}),
    (WIPER, {}),
    (CUP, {}),
    (CUP, {"segments": 12}),
    (SCOOPER, {}),
    (BED, {}),
    (BED, {"pillow": "false"}),
]
CASE_IDS = ["scratcher", "wiper", "cup", "cup-12", "scooper", "bed", "bed-no-pillow"]

NEW_TOOLS = ["scratcher", "wiper", "cup", "scooper"]
ROBOTS = ["jaco", "pr2", "baxter", "sawyer", "panda"]

# Cup (template defaults) and the drinking task's water.
CUP_INNER_R = 0.038
CUP_WALL = 0.01
CUP_RIM = 0.115
PARTICLE_RADIUS = 0.005
PARTICLE_MASS = 0.001
# The 4 x 4 x 4 grid recommended in specs/tools/cup.yaml: first point (-0.015, -0.015, 0.006), pitch 0.01.
WATER_GRID = [
    (-0.015 + 0.01 * i, -0.015 + 0.01 * j, 0.006 + 0.01 * k) for i in range(4) for j in range(4) for k in range(4)
]

MATTRESS_TOP = 0.73


# --------------------------------------------------------------------------------------------
# helpers


@cache
def _render_text(template: str, items: tuple) -> str:
    return xacro.process_file(str(TEMPLATES / template), mappings={k: str(v) for k, v in items}).toprettyxml(
        indent="  "
    )


def render_text(template: str, **args) -> str:
    return _render_text(template, tuple(sorted(args.items())))


def render(template: str, out_dir: Path, **args) -> Path:
    stem = Path(template).name.replace(".urdf.xacro", "")
    suffix = "".join(f"_{k}-{v}" for k, v in sorted(args.items()))
    path = out_dir / f"{stem}{suffix}.urdf"
    if not path.exists():
        path.write_text(render_text(template, **args))
    return path


def link_indices(cid: int, body: int) -> dict[str, int]:
    names = {pb.getBodyInfo(body, physicsClientId=cid)[0].decode(): -1}
    for j in range(pb.getNumJoints(body, physicsClientId=cid)):
        names[pb.getJointInfo(body, j, physicsClientId=cid)[12].decode()] = j
    return names


def joint_indices(cid: int, body: int) -> dict[str, int]:
    return {
        pb.getJointInfo(body, j, physicsClientId=cid)[1].decode(): j
        for j in range(pb.getNumJoints(body, physicsClientId=cid))
    }


def link_frame(cid: int, body: int, link: int):
    """URDF link frame (not the inertial frame) in the world."""
    if link == -1:
        pos, orn = pb.getBasePositionAndOrientation(body, physicsClientId=cid)
        ipos, iorn = pb.getDynamicsInfo(body, -1, physicsClientId=cid)[3:5]
        inv = pb.invertTransform(ipos, iorn)
        return pb.multiplyTransforms(pos, orn, *inv)
    ls = pb.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=cid)
    return ls[4], ls[5]


def subtree(cid: int, body: int, root: int) -> set[int]:
    """Link ``root`` and every link below it."""
    parents = {
        j: pb.getJointInfo(body, j, physicsClientId=cid)[16] for j in range(pb.getNumJoints(body, physicsClientId=cid))
    }
    out = {root}
    grew = True
    while grew:
        grew = False
        for j, p in parents.items():
            if p in out and j not in out:
                out.add(j)
                grew = True
    return out


def ray_hit(cid: int, start, end):
    pb.performCollisionDetection(physicsClientId=cid)
    hit = pb.rayTest(list(start), list(end), physicsClientId=cid)[0]
    assert hit[0] >= 0, f"ray {start} -> {end} hit nothing"
    return np.array(hit[3])


def total_mass(model: yourdfpy.URDF) -> float:
    return sum(link.inertial.mass for link in model.robot.links)


def in_frame(cid: int, body: int, points) -> np.ndarray:
    """World points in the body's base (link) frame."""
    inv = pb.invertTransform(*link_frame(cid, body, -1))
    return np.array([pb.multiplyTransforms(*inv, p, (0, 0, 0, 1))[0] for p in points])


@pytest.fixture(scope="module")
def out_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("task_templates")


@pytest.fixture(scope="module")
def library() -> Library:
    return Library()


# --------------------------------------------------------------------------------------------
# every template


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_check_urdf_passes(template, args, out_dir):
    path = render(template, out_dir, **args)
    res = subprocess.run([str(CHECK_URDF), str(path)], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Successfully Parsed XML" in res.stdout


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_lint_clean(template, args):
    assert lint_urdf(render_text(template, **args), template=template) == []


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_pybullet_loads_without_warnings(template, args, out_dir, cid):
    body, text = load_quiet(cid, render(template, out_dir, **args))
    assert body >= 0
    assert "warning" not in text.lower(), text
    assert "error" not in text.lower(), text


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_yourdfpy_loads(template, args, out_dir):
    model = yourdfpy.URDF.load(str(render(template, out_dir, **args)), build_scene_graph=True, load_meshes=False)
    assert model.validate()
    assert len(model.robot.links) >= 2


@pytest.mark.parametrize("template,args", CASES, ids=CASE_IDS)
def test_conventions(template, args):
    """Positive masses, physically valid inertias, primitives only, every joint fixed (the parts
    are rigid), and the header comment documents frames and args."""
    root = ET.fromstring(render_text(template, **args))
    assert_links_physical(root)
    assert {j.get("type") for j in root.iter("joint")} == {"fixed"}
    header = (TEMPLATES / template).read_text().split("-->", 1)[0]
    for word in ("Frame", "Args"):
        assert word in header, f"{template}: header comment lacks '{word}'"


# --------------------------------------------------------------------------------------------
# library parts


@pytest.mark.parametrize("tool", NEW_TOOLS)
def test_tool_part_mass_and_frames(tool, library, out_dir):
    """The part loads (its semantic links exist in the URDF), its template's total mass matches
    mass_kg within 1 %, and the root's inertial sits at the tool frame so the base pose PyBullet
    reports is the frame the grips refer to."""
    part = library.get("tools", tool).part
    assert part.reference_link in part.links
    model = yourdfpy.URDF.load(
        str(render(part.template.path, out_dir, **part.template.params)), build_scene_graph=True, load_meshes=False
    )
    assert model.base_link == part.base_link
    assert total_mass(model) == pytest.approx(part.mass_kg, rel=0.01)
    np.testing.assert_allclose(model.link_map[part.base_link].inertial.origin, np.eye(4), atol=1e-12)


@pytest.mark.parametrize(
    "tool,link,xyz",
    [
        ("scratcher", "scratcher_tip", (0.075, 0, 0)),
        ("wiper", "wiper_pad", (0, 0, -0.035)),
        ("wiper", "wiper_cloth", (0, 0, -0.0425)),
        ("cup", "cup_top", (0, 0, CUP_RIM)),
        ("scooper", "scooper_blade", (0.135, 0, 0.003)),
    ],
)
def test_tool_frames(tool, link, xyz, out_dir):
    model = yourdfpy.URDF.load(
        str(render(f"tools/{tool}.urdf.xacro", out_dir)), build_scene_graph=True, load_meshes=False
    )
    expected = np.eye(4)
    expected[:3, 3] = xyz
    np.testing.assert_allclose(model.get_transform(link, tool), expected, atol=1e-9)


def test_bed_part(library):
    part = library.get("furniture", "bed").part
    assert part.static and part.friction == 5.0
    assert part.links == {"mattress": "mattress_top"}


@pytest.mark.parametrize("robot", ROBOTS)
def test_robot_grips_and_finger_positions(robot, library, out_dir, cid):
    """Every robot has a grip and, on every gripper side, finger positions for every new tool,
    each within the finger joints' limits."""
    part = library.get("robots", robot).part
    body, _ = load_quiet(cid, render(part.template.path, out_dir))
    joints = joint_indices(cid, body)
    for tool in NEW_TOOLS:
        assert tool in part.grips
        for side, gripper in part.gripper.items():
            q = gripper.positions[tool]
            qs = q if isinstance(q, list) else [q] * len(gripper.joints)
            assert len(qs) == len(gripper.joints)
            for name, value in zip(gripper.joints, qs):
                lo, hi = pb.getJointInfo(body, joints[name], physicsClientId=cid)[8:10]
                assert lo - 1e-9 <= value <= hi + 1e-9, (robot, side, tool, name, value, (lo, hi))


# --------------------------------------------------------------------------------------------
# grips: each robot holds each tool in its fingers, without its hand cutting into the tool

APPROACH_AXIS = {"pr2": 0}  # the tool-mount axis pointing out of the hand; z for the others
CLOSING_AXIS = 1  # the fingers close along the tool mount's y on every robot
ACROSS_AXIS = {"pr2": 2}  # the third axis (the PR2 palm's up); x for the others
WIPES_FROM_ABOVE = {
    "pr2",
    "jaco",
    "panda",
    "sawyer",
    "baxter",
}  # these hold the cloth out along the approach (wiping from above)


@pytest.mark.parametrize("tool", NEW_TOOLS)
@pytest.mark.parametrize("robot", ROBOTS)
def test_grip_holds_tool_without_overlap(robot, tool, library, out_dir, cid):
    """The robot (template at its base pose, arm at zero) with its fingers at the tool's gripper
    position; the tool placed at tool-mount frame ∘ grip. No finger or hand link overlaps the tool
    (getClosestPoints at distance 0 is empty), fingers on both sides are within 1 cm of it, and
    the tool points as intended: scratcher tip and scooper blade out along the approach axis, on
    the hand's centre line; the cup's axis across both the approach and the closing axis (an
    upright cup means a horizontal hand); the wiper's cloth out along the approach on every robot
    that has it (the reference holds it across on PR2; there the forearm lay on the mattress)."""
    part = library.get("robots", robot).part
    tpart = library.get("tools", tool).part
    grip = part.grips[tool]
    body, _ = load_quiet(cid, render(part.template.path, out_dir))
    joints, links = joint_indices(cid, body), link_indices(cid, body)
    approach, across = APPROACH_AXIS.get(robot, 2), ACROSS_AXIS.get(robot, 0)
    for side, gripper in part.gripper.items():
        _, arm = part.arm_for(side)
        q = gripper.positions[tool]
        for name, value in zip(gripper.joints, q if isinstance(q, list) else [q] * len(gripper.joints)):
            pb.resetJointState(body, joints[name], value, physicsClientId=cid)
        mount = link_frame(cid, body, links[arm.tool_mount])
        pos, orn = pb.multiplyTransforms(*mount, grip.position_m, pb.getQuaternionFromEuler(grip.rpy_rad))
        tool_body, _ = load_quiet(cid, render(tpart.template.path, out_dir, **tpart.template.params), pos, orn)
        # The hand: the link carrying the fingers and everything below it; each finger is a
        # gripper joint hanging from that link, with its subtree.
        hand_root = pb.getJointInfo(body, joints[gripper.joints[0]], physicsClientId=cid)[16]
        hand = subtree(cid, body, hand_root)
        fingers = [
            subtree(cid, body, joints[name])
            for name in gripper.joints
            if pb.getJointInfo(body, joints[name], physicsClientId=cid)[16] == hand_root
        ]
        assert len(fingers) >= 2
        overlap = [p for p in pb.getClosestPoints(tool_body, body, 0.0, physicsClientId=cid) if p[4] in hand]
        assert overlap == [], [
            (robot, side, tool, pb.getJointInfo(body, p[4], physicsClientId=cid)[12], p[8]) for p in overlap
        ]
        near = [p[4] for p in pb.getClosestPoints(tool_body, body, 0.01, physicsClientId=cid)]
        touching = [f for f in fingers if any(link in f for link in near)]
        assert len(touching) >= 2, (robot, side, tool, "not held between the fingers")
        # Where the tool points, in the tool-mount frame.
        tlinks = link_indices(cid, tool_body)
        inv = pb.invertTransform(*mount)
        base_local = np.array(pb.multiplyTransforms(*inv, *link_frame(cid, tool_body, -1))[0])
        ref = tpart.links["top" if tool == "cup" else tpart.reference_link]
        ref_local = np.array(pb.multiplyTransforms(*inv, *link_frame(cid, tool_body, tlinks[ref]))[0])
        d = ref_local - base_local
        if tool == "cup" or (tool == "wiper" and robot not in WIPES_FROM_ABOVE):  # straight across
            assert abs(d[approach]) < 1e-6 and abs(d[CLOSING_AXIS]) < 1e-6
            assert abs(d[across]) == pytest.approx(CUP_RIM if tool == "cup" else 0.0425)
        else:  # the working end lies out along the approach axis, on the hand's centre line
            assert d[approach] > 0.03
            assert abs(ref_local[CLOSING_AXIS]) < 1e-6
        pb.removeBody(tool_body, physicsClientId=cid)


# --------------------------------------------------------------------------------------------
# cup


def test_cup_shape(out_dir, cid):
    cup, _ = load_quiet(cid, render(CUP, out_dir))
    # (PyBullet's AABBs carry a 1 mm margin on every side.)
    lo, hi = (np.array(v) for v in pb.getAABB(cup, -1, physicsClientId=cid))
    assert hi[2] - lo[2] - 0.002 == pytest.approx(0.125, abs=1e-4)  # 12.5 cm tall like the reference
    assert hi[0] - lo[0] - 0.002 == pytest.approx(0.097, abs=0.002)  # ~9.6 cm across
    assert lo[2] + 0.001 == pytest.approx(-0.01, abs=1e-4)
    # Open on top; the floor's top is at the frame origin all over the inside.
    for x, y in [(0, 0), (0.03, 0), (-0.02, 0.02), (0.0, -0.035)]:
        assert ray_hit(cid, (x, y, 0.5), (x, y, -0.5))[2] == pytest.approx(0.0, abs=1e-4)
    # The wall is closed all round from the floor to the rim, its inner face at the inner radius.
    for z in (0.002, 0.05, 0.11):
        for k in range(48):
            a = 2 * PI * k / 48
            hit = ray_hit(cid, (0, 0, z), (0.2 * math.cos(a), 0.2 * math.sin(a), z))
            assert CUP_INNER_R - 1e-4 < math.hypot(hit[0], hit[1]) < CUP_INNER_R / math.cos(PI / 16) + 1e-4
    # From outside, the wall is 1 cm thick.
    hit = ray_hit(cid, (0.3, 0, 0.05), (0, 0, 0.05))
    assert hit[0] == pytest.approx(CUP_INNER_R + CUP_WALL, abs=1e-4)


def _water(cid: int, cup: int) -> list[int]:
    shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=PARTICLE_RADIUS, physicsClientId=cid)
    pos, orn = link_frame(cid, cup, -1)
    return [
        pb.createMultiBody(
            PARTICLE_MASS, shape, -1, pb.multiplyTransforms(pos, orn, p, (0, 0, 0, 1))[0], physicsClientId=cid
        )
        for p in WATER_GRID
    ]


def _setup(cid: int):
    pb.setGravity(0, 0, -9.81, physicsClientId=cid)
    pb.setTimeStep(0.02, physicsClientId=cid)
    pb.setPhysicsEngineParameter(numSubSteps=0, numSolverIterations=10, physicsClientId=cid)


def test_cup_holds_water_upright(out_dir, cid):
    """The 64 particles, created on the recommended grid, stay in the cup held still for 3 s
    (0.02 s steps, 10 solver iterations, no sub-steps), lying on its floor."""
    _setup(cid)
    cup, _ = load_quiet(cid, render(CUP, out_dir), pos=(0, 0, 1.0))
    water = _water(cid, cup)
    for _ in range(150):
        pb.stepSimulation(physicsClientId=cid)
    local = in_frame(cid, cup, [pb.getBasePositionAndOrientation(b, physicsClientId=cid)[0] for b in water])
    r = np.hypot(local[:, 0], local[:, 1])
    assert (r < CUP_INNER_R).all(), r.max()
    assert local[:, 2].min() > 0.0 and local[:, 2].max() < 0.03
    # The floor is one flat box: the resting water has at most 2 contact points with the cup per
    # particle on average (16 floor sectors meeting at the axis gave ~190 for the 64 particles,
    # up to 13 for one near the axis, all of them rows for the solver every physics step).
    contacts = sum(len(pb.getContactPoints(bodyA=cup, bodyB=b, physicsClientId=cid)) for b in water)
    assert contacts <= 2 * len(water), contacts


@pytest.mark.parametrize("tilt_deg", [30, 45, 60, 75, 120])
def test_cup_pours_when_tilted_but_never_leaks(out_dir, cid, tilt_deg):
    """As the runtime holds it: a dynamic cup on a fixed constraint (max force 500). After the
    water has settled the constraint turns the cup about x over 0.6 s. At 60 degrees all the
    water stays in (at 30-75 degrees too); at 120 degrees most of it pours out over the rim. No
    particle ever passes through the wall or the floor."""
    _setup(cid)
    cup, _ = load_quiet(cid, render(CUP, out_dir), pos=(0, 0, 1.0), fixed=False)
    hold = pb.createConstraint(cup, -1, -1, -1, pb.JOINT_FIXED, [0, 0, 0], [0, 0, 0], [0, 0, 1.0], physicsClientId=cid)
    pb.changeConstraint(hold, maxForce=500, physicsClientId=cid)
    water = _water(cid, cup)
    history = []
    for step in range(250):
        if 75 <= step < 105:
            angle = math.radians(tilt_deg) * (step - 74) / 30
            pb.changeConstraint(
                hold,
                jointChildFrameOrientation=pb.getQuaternionFromEuler([-angle, 0, 0]),
                maxForce=500,
                physicsClientId=cid,
            )
        pb.stepSimulation(physicsClientId=cid)
        history.append(in_frame(cid, cup, [pb.getBasePositionAndOrientation(b, physicsClientId=cid)[0] for b in water]))
    roll = pb.getEulerFromQuaternion(pb.getBasePositionAndOrientation(cup, physicsClientId=cid)[1])[0]
    assert abs(roll) == pytest.approx(math.radians(tilt_deg), abs=0.02)
    h = np.array(history)
    r = np.hypot(h[..., 0], h[..., 1])
    through_wall = (r > CUP_INNER_R + CUP_WALL / 2) & (h[..., 2] < CUP_RIM - 0.01)
    through_floor = (h[..., 2] < -0.005) & (r < CUP_INNER_R + CUP_WALL)
    assert not through_wall.any() and not through_floor.any()
    inside = (r[-1] < CUP_INNER_R + CUP_WALL / 2) & (h[-1, :, 2] < CUP_RIM)
    if tilt_deg < 90:
        assert inside.all()
    else:
        assert inside.sum() <= 16


# --------------------------------------------------------------------------------------------
# bed


def test_bed_size_and_mattress(out_dir, cid):
    path = render(BED, out_dir)
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    np.testing.assert_allclose(model.get_transform("mattress_top", "bed")[:3, 3], [0, 0, MATTRESS_TOP])
    bed, _ = load_quiet(cid, path, pos=(-0.1, 0, 0))  # where the bed tasks put it
    lo, hi = (np.array(v) + m for v, m in zip(pb.getAABB(bed, -1, physicsClientId=cid), (0.001, -0.001)))
    np.testing.assert_allclose(hi - lo, [1.06, 2.36, 1.16], atol=1e-4)  # (less PyBullet's 1 mm AABB margin)
    assert lo[2] == pytest.approx(0.0, abs=1e-4)
    pos, _ = link_frame(cid, bed, link_indices(cid, bed)["mattress_top"])
    np.testing.assert_allclose(pos, [-0.1, 0, MATTRESS_TOP], atol=1e-9)
    # The mattress's top face, across and along the bed (away from the pillow).
    for x, y in [(0, 0), (0.4, 0.3), (-0.4, -1.0), (0.35, -0.6)]:
        assert ray_hit(cid, (x - 0.1, y, 2), (x - 0.1, y, 0))[2] == pytest.approx(MATTRESS_TOP, abs=1e-4)
    # The pillow at the head end (+y), the head and foot boards up to 1.16 m.
    assert ray_hit(cid, (-0.1, 0.7, 2), (-0.1, 0.7, 0))[2] == pytest.approx(MATTRESS_TOP + 0.08, abs=1e-4)
    for y in (1.155, -1.155):
        assert ray_hit(cid, (-0.1, y, 2), (-0.1, y, 0))[2] == pytest.approx(1.16, abs=1e-4)
    # Args: no pillow; another mattress height.
    flat, _ = load_quiet(cid, render(BED, out_dir, pillow="false", mattress_top_m=0.6), pos=(5, 0, 0))
    assert ray_hit(cid, (5, 0.7, 2), (5, 0.7, 0))[2] == pytest.approx(0.6, abs=1e-4)
    pos, _ = link_frame(cid, flat, link_indices(cid, flat)["mattress_top"])
    np.testing.assert_allclose(pos, [5, 0, 0.6], atol=1e-9)


def test_box_dropped_on_bed_rests_on_mattress(out_dir, cid):
    """A 20 kg box dropped from 1.2 m (bed friction 5, as while the person settles) comes to rest
    on the mattress's top face."""
    pb.setGravity(0, 0, -9.81, physicsClientId=cid)
    pb.setTimeStep(0.02, physicsClientId=cid)
    bed, _ = load_quiet(cid, render(BED, out_dir), pos=(-0.1, 0, 0))
    pb.changeDynamics(bed, -1, lateralFriction=5.0, physicsClientId=cid)
    half = (0.15, 0.25, 0.1)
    shape = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=list(half), physicsClientId=cid)
    box = pb.createMultiBody(20.0, shape, -1, [-0.2, -0.3, 1.2], physicsClientId=cid)
    for _ in range(150):
        pb.stepSimulation(physicsClientId=cid)
    pos, _ = pb.getBasePositionAndOrientation(box, physicsClientId=cid)
    vel, _ = pb.getBaseVelocity(box, physicsClientId=cid)
    assert pos[2] - half[2] == pytest.approx(MATTRESS_TOP, abs=0.005)
    assert np.linalg.norm(vel) < 0.01
    assert pos[0] == pytest.approx(-0.2, abs=0.01) and pos[1] == pytest.approx(-0.3, abs=0.01)

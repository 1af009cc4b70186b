"""The parametric person: real xacro renders loaded in real pybullet (DIRECT), checked against the
reference's numbers (paper §III-A): joints, masses, standing height, landmark heights, posture
baking, urdfdom's check_urdf and the mouth point's clearance from the face."""

from __future__ import annotations

import math
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

try:
    from assistive_compiler.person import body, skeleton
except ModuleNotFoundError:  # running from a checkout without the package installed
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from assistive_compiler.person import body, skeleton

import pybullet as p
import xacro

SEXES = ("male", "female")
MASS = {"male": 78.4, "female": 62.5}
HEIGHT = {"male": 1.733, "female": 1.584}
# Facts 3.1: standing landmark heights (shoulder, elbow, wrist, head link, hip, knee, ankle).
LANDMARK_HEIGHTS = {
    "male": dict(shoulder=1.387, elbow=1.108, wrist=0.818, head=1.534, hip=0.927, knee=0.503, ankle=0.075),
    "female": dict(shoulder=1.280, elbow=1.016, wrist=0.755, head=1.400, hip=0.848, knee=0.457, ankle=0.068),
}
REVOLUTE = (
    [
        f"right_{j}"
        for j in (
            "pecs_x",
            "pecs_y",
            "pecs_z",
            "shoulder_x",
            "shoulder_y",
            "shoulder_z",
            "elbow",
            "forearm",
            "wrist_x",
            "wrist_y",
        )
    ]
    + [
        f"left_{j}"
        for j in (
            "pecs_x",
            "pecs_y",
            "pecs_z",
            "shoulder_x",
            "shoulder_y",
            "shoulder_z",
            "elbow",
            "forearm",
            "wrist_x",
            "wrist_y",
        )
    ]
    + ["neck", "head_x", "head_y", "head_z", "waist_x", "waist_y", "waist_z"]
    + [
        f"{s}_{j}"
        for s in ("right", "left")
        for j in ("hip_x", "hip_y", "hip_z", "knee", "ankle_x", "ankle_y", "ankle_z")
    ]
)


def render(mappings: dict[str, str]) -> str:
    doc = xacro.process_file(str(body.PERSON_TEMPLATE), mappings=dict(mappings))
    return doc.toprettyxml(indent="  ")


@pytest.fixture(scope="module")
def urdfs(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("person")
    paths = {}
    for sex in SEXES:
        paths[sex] = out / f"{sex}.urdf"
        paths[sex].write_text(render(body.body_measurements(sex).xacro_args()))
    return paths


@pytest.fixture()
def client():
    cid = p.connect(p.DIRECT)
    yield cid
    p.disconnect(cid)


def load(cid: int, path: Path, sex: str, fixed: bool = True) -> int:
    """Standing on z = 0: the chest frame at the body model's chest height."""
    z = body.body_measurements(sex).chest_height_m
    return p.loadURDF(str(path), basePosition=[0, 0, z], useFixedBase=fixed, physicsClientId=cid)


def link_index(cid: int, bid: int) -> dict[str, int]:
    idx = {p.getBodyInfo(bid, physicsClientId=cid)[0].decode(): -1}
    for i in range(p.getNumJoints(bid, physicsClientId=cid)):
        idx[p.getJointInfo(bid, i, physicsClientId=cid)[12].decode()] = i
    return idx


def frame_pose(cid: int, bid: int, i: int):
    if i < 0:
        return p.getBasePositionAndOrientation(bid, physicsClientId=cid)
    s = p.getLinkState(bid, i, computeForwardKinematics=True, physicsClientId=cid)
    return s[4], s[5]


@pytest.mark.parametrize("sex", SEXES)
def test_joints(urdfs, client, sex):
    bid = load(client, urdfs[sex], sex)
    n = p.getNumJoints(bid, physicsClientId=client)
    assert n == 42
    infos = [p.getJointInfo(bid, i, physicsClientId=client) for i in range(n)]
    names = [info[1].decode() for info in infos]
    revolute = [info[1].decode() for info in infos if info[2] == p.JOINT_REVOLUTE]
    fixed = [info[1].decode() for info in infos if info[2] == p.JOINT_FIXED]
    assert revolute == REVOLUTE and fixed == ["stomach"]
    # Reference order (index 24 is the fixed stomach) and link naming.
    assert names == list(skeleton.JOINT_NAMES) and names[24] == "stomach"
    assert [info[12].decode() for info in infos] == list(skeleton.LINK_NAMES)
    links = link_index(client, bid)
    assert set(skeleton.LANDMARKS) <= set(links)
    assert p.getBodyInfo(bid, physicsClientId=client)[0].decode() == "chest"
    # Axes and limits equal the reference's table.
    unit = {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1)}
    for info in infos:
        name = info[1].decode()
        if name == "stomach":
            continue
        lo, hi = skeleton.JOINT_LIMITS_DEG[name]
        assert info[8] == pytest.approx(math.radians(lo)) and info[9] == pytest.approx(math.radians(hi))
        assert info[13] == pytest.approx(unit[skeleton.JOINT_AXES[name]])
        assert info[10] > 0 and info[11] > 0  # effort, velocity
    assert skeleton.JOINT_AXES["right_shoulder_x"] == "y" and skeleton.JOINT_AXES["right_shoulder_y"] == "x"
    assert sum(len(g) for g in skeleton.JOINT_GROUPS.values()) == 41
    assert len(skeleton.JOINT_GROUPS["right_arm"]) == 10 and skeleton.JOINT_GROUPS["head"] == (
        "neck",
        "head_x",
        "head_y",
        "head_z",
    )


@pytest.mark.parametrize("sex", SEXES)
def test_total_mass(urdfs, client, sex):
    # pybullet reports mass 0 for a fixed base, so weigh a free-base copy.
    bid = load(client, urdfs[sex], sex, fixed=False)
    masses = [
        p.getDynamicsInfo(bid, i, physicsClientId=client)[0]
        for i in range(-1, p.getNumJoints(bid, physicsClientId=client))
    ]
    assert min(masses) > 0
    assert sum(masses) == pytest.approx(MASS[sex], rel=1e-3)
    assert body.body_measurements(sex).total_mass_kg == pytest.approx(MASS[sex], rel=1e-12)
    # A different mass scales every segment.
    assert body.body_measurements(sex, mass_kg=90.0).total_mass_kg == pytest.approx(90.0, rel=1e-12)


@pytest.mark.parametrize("sex", SEXES)
def test_standing_height_and_landmarks(urdfs, client, sex):
    bid = load(client, urdfs[sex], sex)
    n = p.getNumJoints(bid, physicsClientId=client)
    aabbs = [p.getAABB(bid, i, physicsClientId=client) for i in range(-1, n)]
    bottom = min(a[0][2] for a in aabbs)
    top = max(a[1][2] for a in aabbs)
    assert top - bottom == pytest.approx(HEIGHT[sex], rel=0.01)
    assert abs(bottom) < 0.01  # the soles are on z = 0
    assert body.body_measurements(sex).standing_height_m == pytest.approx(HEIGHT[sex], abs=1e-9)

    links = link_index(client, bid)
    model = body.body_measurements(sex).standing_landmark_positions()
    for key, expected in LANDMARK_HEIGHTS[sex].items():
        names = [key] if key == "head" else [f"right_{key}", f"left_{key}"]
        for name in names:
            pos = frame_pose(client, bid, links[name])[0]
            assert pos[2] == pytest.approx(expected, abs=0.02), name
            assert pos == pytest.approx(model[name], abs=1e-6), name
    # Right is -X.
    assert (
        frame_pose(client, bid, links["right_shoulder"])[0][0]
        < 0
        < frame_pose(client, bid, links["left_shoulder"])[0][0]
    )


def test_fixed_joints_bake_posture(tmp_path, client):
    m = body.body_measurements("male")
    path = tmp_path / "bent.urdf"
    path.write_text(render(m.xacro_args(fixed_joints="right_elbow=-1.5708")))
    bid = load(client, path, "male")
    infos = {
        p.getJointInfo(bid, i, physicsClientId=client)[1].decode(): p.getJointInfo(bid, i, physicsClientId=client)
        for i in range(p.getNumJoints(bid, physicsClientId=client))
    }
    assert len(infos) == 42
    assert infos["right_elbow"][2] == p.JOINT_FIXED
    assert infos["right_elbow"][12].decode() == "right_elbow_link"
    assert infos["left_elbow"][2] == p.JOINT_REVOLUTE
    assert sum(info[2] == p.JOINT_REVOLUTE for info in infos.values()) == 40
    links = link_index(client, bid)
    elbow = frame_pose(client, bid, links["right_elbow"])[0]
    wrist = frame_pose(client, bid, links["right_wrist"])[0]
    d = m.forearm_radius + m.forearm_length
    # Elbow -90 deg about x swings the forearm from straight down to straight ahead (-Y).
    assert wrist == pytest.approx((elbow[0], elbow[1] - d, elbow[2]), abs=1e-4)
    assert elbow == pytest.approx(m.standing_landmark_positions()["right_elbow"], abs=1e-6)
    # The Python helper writes the same string.
    assert body.format_fixed_joints({"right_elbow": -1.5708}) == "right_elbow=-1.5708"


@pytest.mark.parametrize("bad", ["right_elbo=0.1", "stomach=0.1", "right_elbow", "right_elbow=abc"])
def test_fixed_joints_rejects_unknown_names(bad):
    with pytest.raises(xacro.XacroException):
        render({"fixed_joints": bad})
    with pytest.raises(ValueError):
        body.format_fixed_joints({"right_elbo": 0.1})


@pytest.mark.parametrize("sex", SEXES)
def test_check_urdf_accepts(urdfs, sex):
    exe = Path(sys.executable).parent / "check_urdf"
    if not exe.is_file():
        pytest.skip("check_urdf (cmeel-urdfdom) not installed next to the interpreter")
    res = subprocess.run([str(exe), str(urdfs[sex])], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Successfully Parsed XML" in res.stdout


@pytest.mark.parametrize("sex", SEXES)
def test_mouth_just_outside_face(urdfs, client, sex):
    m = body.body_measurements(sex)
    bid = load(client, urdfs[sex], sex)
    head = link_index(client, bid)["head"]
    pos, orn = frame_pose(client, bid, head)
    mouth = p.multiplyTransforms(pos, orn, m.mouth_offset_m, (0, 0, 0, 1))[0]
    probe_radius = 1e-4
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=probe_radius, physicsClientId=client)
    probe = p.createMultiBody(0, shape, basePosition=mouth, physicsClientId=client)
    points = p.getClosestPoints(probe, bid, 0.1, linkIndexB=head, physicsClientId=client)
    assert points, "no head geometry within 10 cm of the mouth"
    gap = min(pt[8] for pt in points) + probe_radius
    assert 0.0 < gap < 0.02
    assert m.mouth_offset_m == ((0.0, -0.11, 0.03) if sex == "male" else (0.0, -0.10, 0.03))


def test_template_defaults_are_the_male_and_args_match():
    male = body.body_measurements("male")
    root = ET.parse(body.PERSON_TEMPLATE).getroot()
    defaults = {el.get("name"): el.get("default") for el in root.iter("{http://www.ros.org/wiki/xacro}arg")}
    declared = set(defaults)
    assert declared == set(body.TEMPLATE_ARGS)
    # The template renders on its own as the reference's 50th-percentile male.
    for name, value in male.xacro_args().items():
        assert float(defaults[name]) == pytest.approx(float(value), rel=1e-12, abs=1e-15), name
    # Same inputs, same bytes.
    assert render(male.xacro_args()) == render(male.xacro_args())
    assert (
        set(male.xacro_args(strength=0.5, skin_rgba=(0.5, 0.4, 0.3, 1.0), fixed_joints={}, cloth_spheres=True))
        == declared
    )


def test_strength_scales_efforts_and_scales_apply():
    def efforts(xml: str) -> dict[str, float]:
        return {
            j.get("name"): float(j.find("limit").get("effort"))
            for j in ET.fromstring(xml).iter("joint")
            if j.get("type") == "revolute"
        }

    m = body.body_measurements("female")
    full, half = efforts(render(m.xacro_args())), efforts(render(m.xacro_args(strength=0.5)))
    assert full.keys() == set(REVOLUTE)
    assert all(half[k] == pytest.approx(0.5 * full[k]) for k in full)
    tall = body.body_measurements("female", height_scale=1.1, radius_scale=1.2)
    assert tall.thigh_length == pytest.approx(0.391 * 1.1) and tall.thigh_radius == pytest.approx(0.0775 * 1.2)
    assert tall.hip_offset == pytest.approx(0.0775 * 1.2 + 0.0145)
    assert tall.standing_height_m > m.standing_height_m
    with pytest.raises(ValueError):
        body.body_measurements("other")  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        body.body_measurements("male", mass_kg=-1.0)


def test_cloth_spheres_add_collision_shapes(tmp_path, client):
    m = body.body_measurements("male")
    path = tmp_path / "cloth.urdf"
    path.write_text(render(m.xacro_args(cloth_spheres=True)))
    bid = load(client, path, "male")
    links = link_index(client, bid)
    for name in ("right_shoulder_y_link", "right_elbow_link", "right_wrist_x_link", "left_elbow_link"):
        assert p.getCollisionShapeData(bid, links[name], physicsClientId=client), name


def test_self_collision_groups():
    groups = skeleton.SELF_COLLISION_GROUPS
    assert set(groups) == {"right_arm", "left_arm", "right_leg", "left_leg"}
    assert groups["right_arm"].links == (
        "right_shoulder_x_link",
        "right_shoulder_y_link",
        "right_shoulder",
        "right_elbow_link",
        "right_elbow",
        "right_wrist_x_link",
        "right_wrist",
    )
    assert "chest" in groups["right_arm"].against and "right_pecs" not in groups["right_arm"].against
    assert "waist" not in groups["right_leg"].against and "left_ankle" in groups["right_leg"].against
    known = {"chest", *skeleton.LINK_NAMES}
    assert all(set(g.links) <= known and set(g.against) <= known for g in groups.values())
    pairs = skeleton.self_collision_pairs()
    assert ("chest", "neck") not in pairs and ("left_wrist", "right_wrist") in pairs

"""The nightstand (the reference implementation (Assistive Gym v1.0): 0.55 x 0.58 m, 0.674 m tall) and mounting a robot on it.

(a) The template renders with its defaults, passes check_urdf, yourdfpy, PyBullet (no warnings)
    and the compiler's lint, has the reference's size, and its `robot_mount` frame sits on the top
    surface's centre with the yaw of `mount_yaw_rad`; a Jaco on that frame clears the nightstand.
(b) The mounting mechanism: Feeding extended with a nightstand beside the wheelchair and
    `robot.mount_on: nightstand` compiles for Jaco with the robot base on the nightstand's mount
    frame, the wheelchair rendered without its Jaco post, and the artifact runs.

Real xacro, PyBullet, check_urdf and compiler; no mocks.
"""

from __future__ import annotations

import ctypes
import math
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
import xacro
import yourdfpy

from assistive_compiler.artifact import Mounted
from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.compile.lint import lint_urdf
from assistive_compiler.library import Library
from assistive_compiler.runtime.env import AssistiveEnv

REPO = Path(__file__).resolve().parents[2]
TEMPLATE = REPO / "templates" / "furniture" / "nightstand.urdf.xacro"
FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"
JACO = REPO / "templates" / "robots" / "jaco.urdf.xacro"
CHECK_URDF = Path(sys.executable).parent / "check_urdf"

WIDTH, DEPTH, HEIGHT = 0.55, 0.58, 0.674
# Beside the wheelchair (at the origin, outer wheel faces at x -0.39), on the person's right
# (-X), level with the front of the seat; the mount frame is at (-0.75, -0.35, 0.674).
NIGHTSTAND_POS = (-0.75, -0.35, 0.0)


# --------------------------------------------------------------------------------------------
# helpers


def render(out_dir: Path, template: Path = TEMPLATE, **args) -> tuple[Path, str]:
    mappings = {k: str(v) for k, v in args.items()}
    text = xacro.process_file(str(template), mappings=mappings).toprettyxml(indent="  ")
    suffix = "".join(f"_{k}-{v}" for k, v in sorted(mappings.items()))
    path = out_dir / f"{template.name.replace('.urdf.xacro', '')}{suffix}.urdf"
    path.write_text(text)
    return path, text


_libc = ctypes.CDLL(None)


@contextmanager
def captured_c_output():
    """Redirect fd 1 and fd 2 (where Bullet's C code prints) into a temp file; the yielded list
    receives the captured text on exit."""
    result: list[str] = []
    sys.stdout.flush()
    sys.stderr.flush()
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        saved = [os.dup(1), os.dup(2)]
        try:
            os.dup2(tmp.fileno(), 1)
            os.dup2(tmp.fileno(), 2)
            yield result
        finally:
            _libc.fflush(None)
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            tmp.seek(0)
            result.append(tmp.read().decode(errors="replace"))


def load_quiet(cid: int, path: Path, pos=(0, 0, 0), orn=(0, 0, 0, 1)) -> tuple[int, str]:
    with captured_c_output() as out:
        body = pb.loadURDF(
            str(path), list(pos), list(orn), useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=cid
        )
    return body, out[0]


def link_frame(cid: int, body: int, name: str):
    for j in range(pb.getNumJoints(body, physicsClientId=cid)):
        if pb.getJointInfo(body, j, physicsClientId=cid)[12].decode() == name:
            ls = pb.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=cid)
            return np.array(ls[4]), np.array(ls[5])
    raise KeyError(name)


def ray_hit(cid: int, start, end) -> np.ndarray:
    pb.performCollisionDetection(physicsClientId=cid)  # refresh the broadphase AABBs
    hit = pb.rayTest(list(start), list(end), physicsClientId=cid)[0]
    assert hit[0] >= 0, f"ray {start} -> {end} hit nothing"
    return np.array(hit[3])


def yaw_matrix(yaw: float) -> np.ndarray:
    return np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]])


# --------------------------------------------------------------------------------------------
# (a) the template


def test_warning_capture_works(cid, tmp_path):
    """Positive control: a link without <inertial> makes PyBullet print a warning."""
    bad = tmp_path / "bad.urdf"
    bad.write_text(
        '<robot name="bad"><link name="a"><visual><geometry><box size="1 1 1"/></geometry></visual></link></robot>'
    )
    _, text = load_quiet(cid, bad)
    assert "warning" in text.lower()


@pytest.mark.parametrize("args", [{}, {"mount_yaw_rad": -math.pi / 2}], ids=["default", "yaw"])
def test_nightstand_urdf_checks(args, tmp_path, cid):
    path, xml = render(tmp_path, **args)
    assert lint_urdf(xml, template="furniture/nightstand.urdf.xacro") == []
    res = subprocess.run([str(CHECK_URDF), str(path)], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Successfully Parsed XML" in res.stdout
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    assert model.validate()
    body, text = load_quiet(cid, path)
    assert body >= 0
    assert "warning" not in text.lower(), text
    assert "error" not in text.lower(), text
    # Conventions: positive masses, physically valid inertias, primitives only, wood colour.
    root = ET.fromstring(xml)
    assert sorted(link.get("name") for link in root.iter("link")) == ["nightstand", "robot_mount"]
    for link in root.iter("link"):
        inertial = link.find("inertial")
        assert float(inertial.find("mass").get("value")) > 0
        i = {k: float(v) for k, v in inertial.find("inertia").attrib.items()}
        ev = np.linalg.eigvalsh(
            [[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]]
        )
        assert ev.min() > 0 and ev[0] + ev[1] >= ev[2] * (1 - 1e-9)
        for geom in link.iter("geometry"):
            assert {child.tag for child in geom} <= {"box", "cylinder", "sphere"}
    assert model.link_map["nightstand"].inertial.mass == pytest.approx(15.0)
    assert model.link_map["robot_mount"].inertial.mass < 0.01
    assert not model.link_map["robot_mount"].collisions and not model.link_map["robot_mount"].visuals
    colours = {v.material.name for v in model.link_map["nightstand"].visuals}
    assert "wood" in colours
    (joint,) = root.iter("joint")
    assert (joint.get("name"), joint.get("type")) == ("robot_mount_joint", "fixed")


def test_nightstand_dimensions_and_mount_frame(tmp_path, cid):
    path, _ = render(tmp_path)
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    expected = np.eye(4)
    expected[2, 3] = HEIGHT
    np.testing.assert_allclose(model.get_transform("robot_mount", "nightstand"), expected, atol=1e-9)
    # In PyBullet, at the task's position: footprint 0.55 x 0.58 centred on the frame, floor to 0.674.
    stand, _ = load_quiet(cid, path, pos=NIGHTSTAND_POS)
    lo, hi = (np.array(v) for v in pb.getAABB(stand, -1, physicsClientId=cid))
    np.testing.assert_allclose(hi - lo, [WIDTH, DEPTH, HEIGHT], atol=0.003)
    np.testing.assert_allclose((hi + lo)[:2] / 2, NIGHTSTAND_POS[:2], atol=1e-3)
    assert lo[2] == pytest.approx(0.0, abs=0.003)
    x0, y0, _ = NIGHTSTAND_POS
    for dx, dy in [(0.2, 0.2), (-0.25, 0.0), (0.0, -0.27), (0.1, 0.1)]:
        assert ray_hit(cid, (x0 + dx, y0 + dy, 2.0), (x0 + dx, y0 + dy, 0.0))[2] == pytest.approx(HEIGHT, abs=1e-3)
    # The drawer front is visual only: the -Y side is the body's (0.01 in under the top).
    assert ray_hit(cid, (x0, y0 - 1.0, 0.4), (x0, y0, 0.4))[1] == pytest.approx(y0 - DEPTH / 2 + 0.01, abs=1e-3)
    pos, orn = link_frame(cid, stand, "robot_mount")
    np.testing.assert_allclose(pos, [x0, y0, HEIGHT], atol=1e-6)
    np.testing.assert_allclose(orn, [0, 0, 0, 1], atol=1e-6)
    # A Jaco on the mount frame clears the nightstand at its base (the collision pocket).
    jaco_path, _ = render(tmp_path, JACO)
    jaco, _ = load_quiet(cid, jaco_path, pos=pos, orn=orn)
    pts = pb.getClosestPoints(jaco, stand, 0.05, linkIndexA=-1, physicsClientId=cid)
    assert min((p[8] for p in pts), default=0.05) > 0.005


@pytest.mark.parametrize("yaw", [-math.pi / 2, math.pi / 2, 0.3])
def test_nightstand_mount_yaw(yaw, tmp_path, cid):
    path, _ = render(tmp_path, mount_yaw_rad=yaw)
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    expected = np.eye(4)
    expected[:3, :3] = yaw_matrix(yaw)
    expected[2, 3] = HEIGHT
    np.testing.assert_allclose(model.get_transform("robot_mount", "nightstand"), expected, atol=1e-9)
    stand, _ = load_quiet(cid, path, pos=(1.0, 2.0, 0.0))
    pos, orn = link_frame(cid, stand, "robot_mount")
    np.testing.assert_allclose(pos, [1.0, 2.0, HEIGHT], atol=1e-6)
    np.testing.assert_allclose(pb.getEulerFromQuaternion(orn.tolist()), [0, 0, yaw], atol=1e-6)


def test_nightstand_part():
    part = Library().get("furniture", "nightstand").part
    assert part.name == "nightstand"
    assert part.template.path == "furniture/nightstand.urdf.xacro"
    assert (part.base_link, part.static, part.mount_link) == ("nightstand", True, "robot_mount")


# --------------------------------------------------------------------------------------------
# (b) mounting Jaco on the nightstand beside the wheelchair


def write_task(directory: Path, nightstand_params: dict | None = None) -> Path:
    x, y, z = NIGHTSTAND_POS
    params = f", params: {nightstand_params}" if nightstand_params else ""
    spec = directory / "feeding_nightstand.yaml"
    spec.write_text(
        f"extends: {FEEDING}\n"
        "scene:\n"
        "  furniture:\n"
        f"    nightstand: {{part: nightstand, position_m: [{x}, {y}, {z}], rpy_deg: [0, 0, 0]{params}}}\n"
        "robot: {mount_on: nightstand}\n"
    )
    return spec


@pytest.fixture(scope="module")
def mounted(tmp_path_factory):
    root = tmp_path_factory.mktemp("nightstand_mount")
    out = root / "out"
    result = compile_task(write_task(root), "jaco", out)
    return out, result.manifest


def test_jaco_mounted_on_nightstand(mounted):
    out, manifest = mounted
    assert manifest.robot_name == "jaco"
    variants = [v.name for v in manifest.person.variants]
    assert manifest.robot.placement == {v: Mounted(mounted_on="nightstand") for v in variants}
    stand = manifest.body("nightstand")
    assert stand.kind == "furniture" and stand.fixed_base
    np.testing.assert_allclose(stand.position, NIGHTSTAND_POS, atol=1e-9)
    mount = np.add(stand.position, (0.0, 0.0, HEIGHT))
    first = manifest.person.variants[0].starts[0]
    np.testing.assert_allclose(first.base_position, mount, atol=1e-6)
    np.testing.assert_allclose(first.base_orientation, [0, 0, 0, 1], atol=1e-6)
    for variant in manifest.person.variants:  # every start, every person, on the same mount
        assert variant.starts
        for s in variant.starts:
            np.testing.assert_allclose(s.base_position, mount, atol=1e-6)
    np.testing.assert_allclose(manifest.body("robot").position, mount, atol=1e-6)
    # Mount params apply only to the furniture the robot is mounted on: the wheelchair has no post.
    chair = ET.parse(out / manifest.body("wheelchair").urdf).getroot()
    assert sorted(link.get("name") for link in chair.iter("link")) == ["seat", "wheelchair"]
    stand_links = {link.get("name") for link in ET.parse(out / stand.urdf).getroot().iter("link")}
    assert "robot_mount" in stand_links


def test_mounted_artifact_runs(mounted):
    out, _ = mounted
    env = AssistiveEnv(out)
    try:
        obs, _ = env.reset(seed=0)
        assert obs.shape == env.observation_space.shape and np.isfinite(obs).all()
        env.action_space.seed(0)
        for _ in range(20):
            obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
            assert np.isfinite(obs).all() and np.isfinite(reward)
            assert not terminated
    finally:
        env.close()


def test_mount_yaw_reaches_the_robot_base(tmp_path):
    """The scene's template params set the mount frame's yaw, and the robot base follows it."""
    yaw = -math.pi / 2  # the reference's wheelchair-mount yaw on the person's right
    result = compile_task(write_task(tmp_path, {"mount_yaw_rad": yaw}), "jaco", tmp_path / "out")
    start = result.manifest.person.variants[0].starts[0]
    np.testing.assert_allclose(start.base_position, np.add(NIGHTSTAND_POS, (0, 0, HEIGHT)), atol=1e-6)
    np.testing.assert_allclose(pb.getEulerFromQuaternion(start.base_orientation), [0, 0, yaw], atol=1e-5)

"""The compiler: a resolved task → an artifact directory (URDFs + ``manifest.json``).

Steps, in order:

1. **Render** every body from its xacro template (the person once per variant, with the task's
   static joints baked into fixed joints at their posture angles).
2. **Lint** each URDF (:mod:`.lint`); a failing scene is refused with the template, element and
   problem named.
3. **Precompute** in a private pybullet DIRECT client: seat the person on the furniture's seat,
   mount the robot, solve IK for the start poses (with collision checks against person and
   furniture), and settle the particles in their container. This is the only place the
   compiler steps physics.
4. **Write** atomically: everything goes to a temporary sibling directory that replaces the
   output only when complete, so a failed compile leaves nothing half-written. The manifest
   records a hash of every input (a later compile of unchanged inputs is a cache hit) and a
   hash of the output bytes. The same inputs always give byte-identical output.
"""

from __future__ import annotations

import hashlib
import math
import os
import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..artifact import (
    Body,
    Manifest,
    ParticleSet,
    Person,
    PersonVariant,
    Robot,
    Sim,
    Success,
    Target,
    TermUse,
    ToolAttachment,
)
from ..errors import Problem, SpecError
from ..library import PERSON_TEMPLATE_RELPATH, Library
from ..paths import display, templates_dir
from ..person.body import body_measurements, format_fixed_joints
from ..resolve import ResolvedTask, resolve
from ..spec.load import LoadedSpec, load_spec
from ..spec.models import Uniform, scalar_bounds
from ..terms.registry import SizeContext, terms
from .lint import lint_urdf
from .merge import merge_fixed_links
from .render import render_template, urdf_info

PACKAGE_DIR = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class CompileResult:
    """What a compile produced and whether it came from the cache."""

    out_dir: Path
    manifest: Manifest
    cache_hit: bool
    seconds: float


def gym_id(task_title: str, robot_title: str) -> str:
    """``assistive_compiler/<Task><Robot>-v1`` (e.g. FeedingJaco-v1)."""
    return f"assistive_compiler/{task_title.replace(' ', '')}{robot_title}-v1"


def default_out_dir(task: str, robot: str) -> Path:
    return Path("generated") / f"{task}-{robot}"


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def input_hash(rt: ResolvedTask) -> str:
    """sha256 over every input that can change the output: spec files, part files, all templates,
    the compiler's own source, and the robot chosen."""
    h = hashlib.sha256(f"assistive-compiler {__version__} robot={rt.robot_name}\n".encode())
    files = list(rt.loaded.files) + [rt.robot.path] + [p.path for p in (*rt.tools.values(), *rt.furniture.values(), *rt.people.values())]
    files += sorted(templates_dir().rglob("*.xacro")) + sorted(PACKAGE_DIR.rglob("*.py"))
    for path in files:
        h.update(str(path.name).encode() + b"\0" + Path(path).read_bytes() + b"\0")
    return h.hexdigest()


def _round(values: Any, digits: int = 6) -> Any:
    """Round floats so the manifest's bytes do not depend on the last bits of a solver."""
    if isinstance(values, (list, tuple)):
        return type(values)(_round(v, digits) for v in values) if isinstance(values, list) else tuple(_round(v, digits) for v in values)
    if isinstance(values, (float, np.floating)):
        r = round(float(values), digits)
        return 0.0 if r == 0 else r
    return values


def _quat_from_rpy(rpy: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """Quaternion (x, y, z, w) of fixed-axis roll, pitch, yaw (URDF convention R = Rz·Ry·Rx)."""
    r, p, y = (a / 2 for a in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


class _Precompute:
    """A private pybullet world used only at compile time."""

    def __init__(self) -> None:
        import pybullet

        self.p = pybullet
        self.client = pybullet.connect(pybullet.DIRECT)

    def close(self) -> None:
        self.p.disconnect(self.client)

    def load(self, path: Path, pos, orn, fixed: bool) -> int:
        return self.p.loadURDF(str(path), pos, orn, useFixedBase=fixed, physicsClientId=self.client)

    def link_index(self, body: int, name: str) -> int:
        """Index of link ``name`` of ``body`` (-1 for the base)."""
        p, c = self.p, self.client
        if p.getBodyInfo(body, physicsClientId=c)[0].decode() == name:
            return -1
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            if p.getJointInfo(body, j, physicsClientId=c)[12].decode() == name:
                return j
        raise KeyError(name)

    def link_pose(self, body: int, link: int):
        """World pose of a link's URDF frame (the base's too, not its centre of mass)."""
        p, c = self.p, self.client
        if link == -1:
            com_pos, com_orn = p.getBasePositionAndOrientation(body, physicsClientId=c)
            inertial_pos, inertial_orn = p.getDynamicsInfo(body, -1, physicsClientId=c)[3:5]
            inv_pos, inv_orn = p.invertTransform(inertial_pos, inertial_orn)
            return p.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)
        s = p.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=c)
        return s[4], s[5]

    def joint_index(self, body: int) -> dict[str, int]:
        p, c = self.p, self.client
        return {p.getJointInfo(body, j, physicsClientId=c)[1].decode(): j for j in range(p.getNumJoints(body, physicsClientId=c))}

    def touching(self, a: int, b: int, margin: float = 0.0) -> bool:
        return bool(self.p.getClosestPoints(a, b, margin, physicsClientId=self.client))


def _fail(rt: ResolvedTask, path: tuple, message: str) -> SpecError:
    return SpecError([Problem(rt.loaded.smap.value(path), message)])


def build(rt: ResolvedTask, out_tmp: Path, lib: Library) -> Manifest:
    """Write the URDFs of ``rt`` into ``out_tmp/urdf`` and return the manifest (without hashes)."""
    spec = rt.spec
    urdf_dir = out_tmp / "urdf"
    urdf_dir.mkdir(parents=True)
    written: dict[str, Path] = {}

    def emit(body_name: str, template: Path, params: dict[str, Any], where) -> Path:
        """Render, lint and write one body; a refusal is located at ``where`` (the part's template line)."""
        xml = render_template(template, params)
        problems = lint_urdf(xml, template=display(template))
        if problems:
            raise SpecError([Problem(where, f"generated URDF refused: {pr}") for pr in problems])
        path = urdf_dir / f"{body_name}.urdf"
        path.write_text(xml)
        written[body_name] = path
        return path

    # 1-2. Render and lint ------------------------------------------------------------------
    robot_part = rt.robot.part
    if robot_part.template is None:
        raise _fail(rt, ("robot", "default"), f"robot '{rt.robot_name}' uses an external URDF; compiling those arrives with the robot library")
    emit("robot", lib.template_path(rt.robot), robot_part.template.params, rt.robot.smap.value(("template", "path")))
    mounted_on = spec.robot.mount_on if robot_part.mountable else None
    for name, use in spec.scene.furniture.items():
        part = rt.furniture[name].part
        params = dict(part.template.params) | dict(use.params)
        if name == mounted_on:
            params |= part.mount_params
        emit(name, lib.template_path(rt.furniture[name]), params, rt.furniture[name].smap.value(("template", "path")))
    for name, use in spec.tools.items():
        part = rt.tools[name].part
        params = dict(part.template.params) | ({"mass_kg": use.mass_kg} if use.mass_kg else {})
        emit(name, lib.template_path(rt.tools[name]), params, rt.tools[name].smap.value(("template", "path")))

    person = spec.person
    movable = set(person.randomize_deg) | set(rt.joint_groups.get("person.policy", {}).get("joints", []))
    movable |= set(_policy_joints(rt))
    if person.control.compliant:
        for ref in person.control.compliant.joints:
            movable |= set(rt.joint_groups[ref]["joints"])
    person_joints = [j for j in rt.person_urdf.movable_joints]
    baked = {j: math.radians(person.joints_deg.get(j, 0.0)) for j in person_joints if j not in movable}
    movable_ordered = [j for j in person_joints if j in movable]
    measurements = {}
    for i, variant in enumerate(person.variants):
        part = rt.people[variant].part
        m = body_measurements(part.sex, part.mass_kg, part.height_scale, part.radius_scale)
        measurements[variant] = m
        args = m.xacro_args() | {"fixed_joints": format_fixed_joints(baked), "skin_rgba": " ".join(repr(float(c)) for c in part.skin_rgba)}
        emit(f"person_{variant}", templates_dir() / PERSON_TEMPLATE_RELPATH, args, rt.loaded.smap.value(("person", "variants", i)))

    # 3. Precompute (on the unmerged bodies) -------------------------------------------------
    pc = _Precompute()
    try:
        manifest = _precompute(rt, pc, written, out_tmp, baked, movable_ordered, measurements, mounted_on)
    finally:
        pc.close()

    # 4. Merge each person's static links into as few rigid links as possible: a seated person
    #    with a movable head goes from 43 links to 5, which is most of a step's physics cost.
    keep = _referenced_person_links(rt)
    for variant in person.variants:
        path = written[f"person_{variant}"]
        merged, _frames = merge_fixed_links(path.read_text(), keep=keep)
        problems = lint_urdf(merged, template=f"merged person '{variant}'")
        if problems:  # pragma: no cover - the merge preserves validity; lint guards it
            raise SpecError([Problem(rt.loaded.smap.value(("person", "variants")), f"merged person URDF refused: {pr}") for pr in problems])
        path.write_text(merged)
    return manifest


def _referenced_person_links(rt: ResolvedTask) -> set[str]:
    """Person links the task refers to (they must survive the merge as links of their own)."""
    found: set[str] = set()

    def visit(value: Any) -> None:
        if isinstance(value, dict):
            if value.get("body") == "person" and "link" in value:
                found.add(value["link"])
            for v in value.values():
                visit(v)
        elif isinstance(value, list):
            for v in value:
                visit(v)

    for term in [*rt.reward, *(t for ts in rt.observations.values() for t in ts)]:
        visit(term.params)
    visit(rt.points)
    visit(rt.scripted)
    return found


def _policy_joints(rt: ResolvedTask) -> list[str]:
    out: list[str] = []
    for ref in rt.spec.person.control.policy_joints:
        out += [j for j in rt.joint_groups[ref]["joints"] if j not in out]
    return out


def _precompute(rt, pc: _Precompute, written, out_tmp, baked, movable, measurements, mounted_on) -> Manifest:
    spec = rt.spec
    p, c = pc.p, pc.client
    p.setGravity(0, 0, spec.sim.gravity_mps2, physicsClientId=c)
    p.setTimeStep(spec.sim.time_step_s, physicsClientId=c)
    rel = lambda path: str(path.relative_to(out_tmp))  # noqa: E731
    bodies: list[Body] = []

    # Furniture at its nominal pose.
    furniture_ids: dict[str, int] = {}
    for name, use in spec.scene.furniture.items():
        part = rt.furniture[name].part
        orn = _quat_from_rpy(tuple(math.radians(a) for a in use.rpy_deg))
        static = part.static if use.static is None else use.static
        furniture_ids[name] = pc.load(written[name], use.position_m, orn, True)
        bodies.append(Body(name=name, kind="furniture", urdf=rel(written[name]), position=_round(use.position_m), orientation=_round(orn),
                           fixed_base=static, gravity=None, friction=use.friction if use.friction is not None else part.friction,
                           position_noise=_round(use.position_noise_m)))

    # Person: seated on the furniture's seat surface, or at an explicit position.
    person_spec = spec.person
    person_orn = _quat_from_rpy(tuple(math.radians(a) for a in person_spec.placement.rpy_deg))
    person_ids: dict[str, int] = {}
    person_pos: dict[str, tuple] = {}
    for variant in person_spec.variants:
        body_name = f"person_{variant}"
        probe = pc.load(written[body_name], (0, 0, 0), person_orn, True)
        if person_spec.placement.seated_on:
            seat_name = person_spec.placement.seated_on
            seat_part = rt.furniture[seat_name].part
            seat_pos, _ = pc.link_pose(furniture_ids[seat_name], pc.link_index(furniture_ids[seat_name], seat_part.seat_link))
            lowest = min(p.getAABB(probe, pc.link_index(probe, link), physicsClientId=c)[0][2] for link in _seat_links(rt))
            pos = (seat_pos[0], seat_pos[1], seat_pos[2] - lowest + 0.002)
            pos = tuple(a + b for a, b in zip(pos, person_spec.placement.offset_m))
        else:
            pos = tuple(person_spec.placement.position_m)
        p.resetBasePositionAndOrientation(probe, pos, person_orn, physicsClientId=c)
        jidx = pc.joint_index(probe)
        for j in movable:
            p.resetJointState(probe, jidx[j], math.radians(person_spec.joints_deg.get(j, 0.0)), physicsClientId=c)
        person_ids[variant], person_pos[variant] = probe, _round(pos)

    # Robot: on the mount, or at a stated base offset.
    robot_part = rt.robot.part
    per_robot = spec.robot.per_robot.get(rt.robot_name)
    offset = per_robot.base_offset_m if per_robot and per_robot.base_offset_m else (0.0, 0.0, 0.0)
    if mounted_on:
        fpart = rt.furniture[mounted_on].part
        mpos, morn = pc.link_pose(furniture_ids[mounted_on], pc.link_index(furniture_ids[mounted_on], fpart.mount_link))
        base_pos, base_orn = tuple(a + b for a, b in zip(mpos, offset)), tuple(morn)
    elif per_robot and per_robot.base_offset_m:
        base_pos, base_orn = tuple(offset), (0.0, 0.0, 0.0, 1.0)
    else:
        raise _fail(rt, ("robot", "default"), f"robot '{rt.robot_name}' is not mountable and task '{spec.name}' gives no per_robot.{rt.robot_name}.base_offset_m; floor base-pose search is not available yet")
    robot_id = pc.load(written["robot"], base_pos, base_orn, True)
    robot_joints = pc.joint_index(robot_id)
    side = spec.robot.arm if spec.robot.arm != "both" else "right"
    _, arm = robot_part.arm_for(side)
    arm_joints = rt.joint_groups["robot.arm"]["joints"]
    infos = {j: p.getJointInfo(robot_id, robot_joints[j], physicsClientId=c) for j in arm_joints}
    lower = [infos[j][8] for j in arm_joints]
    upper = [infos[j][9] for j in arm_joints]

    # Tools and the grip transform.
    tool_ids: dict[str, int] = {}
    attachments: list[ToolAttachment] = []
    tool_name = next(iter(spec.tools), None)
    for name, use in spec.tools.items():
        tpart = rt.tools[name].part
        grip = robot_part.grips[tpart.name]
        hand_side, hand = robot_part.arm_for(use.hand)
        tool_ids[name] = pc.load(written[name], (0, 0, -10), (0, 0, 0, 1), True)
        attachments.append(ToolAttachment(body=name, parent_link=hand.tool_mount, position=_round(grip.position_m),
                                          orientation=_round(_quat_from_rpy(grip.rpy_rad)),
                                          links=dict(tpart.links) | {"base": tpart.base_link}))
        bodies.append(Body(name=name, kind="tool", urdf=rel(written[name]), position=(0.0, 0.0, 0.0), orientation=(0.0, 0.0, 0.0, 1.0),
                           fixed_base=False, gravity=use.gravity_mps2))

    # 3b. Start configurations: IK for noisy tool poses, per person variant ------------------
    start = spec.robot.start
    tool_orn = _quat_from_rpy(tuple(math.radians(a) for a in start.tool_rpy_deg))
    if tool_name:
        att = attachments[0]
        inv_pos, inv_orn = p.invertTransform(att.position, att.orientation)
    else:
        inv_pos, inv_orn = (0, 0, 0), (0, 0, 0, 1)
    ee_link = pc.link_index(robot_id, arm.tool_mount)
    movable_idx = [j for j in range(p.getNumJoints(robot_id, physicsClientId=c)) if p.getJointInfo(robot_id, j, physicsClientId=c)[2] != p.JOINT_FIXED]
    arm_idx = [robot_joints[j] for j in arm_joints]
    ik_pos_in_movable = [movable_idx.index(i) for i in arm_idx]
    rng = np.random.default_rng(int(rt.loaded.spec.name.encode().hex(), 16) % (2**32))
    obstacles = list(furniture_ids.values())
    variants_out: list[PersonVariant] = []
    particle_sets: list[ParticleSet] = []
    for vi, variant in enumerate(person_spec.variants):
        for other, pid in person_ids.items():  # only this variant in the scene
            p.resetBasePositionAndOrientation(pid, person_pos[other] if other == variant else (0, 0, -20), person_orn, physicsClientId=c)
        configs: list[list[float]] = []
        reached: list[tuple] = []
        for s in range(start.samples):
            noise = np.zeros(3) if s == 0 else rng.uniform(-start.noise_m, start.noise_m, 3)
            goal = tuple(np.asarray(start.tool_position_m) + noise)
            ee_pos, ee_orn = p.multiplyTransforms(goal, tool_orn, inv_pos, inv_orn)
            q = _solve_ik(pc, robot_id, ee_link, ee_pos, ee_orn, arm_idx, ik_pos_in_movable, lower, upper, rng)
            if q is None:
                continue
            if any(pc.touching(robot_id, o) for o in obstacles + [person_ids[variant]]):
                continue
            tool_ok = True
            for name, tid in tool_ids.items():
                p.resetBasePositionAndOrientation(tid, goal, tool_orn, physicsClientId=c)
                tool_ok &= not pc.touching(tid, person_ids[variant])
            if tool_ok:
                configs.append(_round(list(q)))
                reached.append(_round(goal))
        if not configs:
            raise _fail(rt, ("robot", "start", "tool_position_m"),
                        f"robot '{rt.robot_name}' cannot reach the start pose {tuple(start.tool_position_m)} (tool rpy {tuple(start.tool_rpy_deg)}°) without collision for person '{variant}'")
        m = measurements[variant]
        offsets = {}
        for tname, target in spec.targets.items():
            if rt.points.get(tname, {}).get("body") == "person":
                offsets[tname] = _round(tuple(target.offset_by_variant.get(variant, target.offset_m)))
        initial = {j: _round(math.radians(person_spec.joints_deg.get(j, 0.0))) for j in movable}
        randomize = {j: _round(tuple(math.radians(a) for a in person_spec.randomize_deg[j].uniform)) for j in movable if j in person_spec.randomize_deg}
        variants_out.append(PersonVariant(name=variant, body=f"person_{variant}", sex=m.sex, mass_kg=_round(m.mass_kg),
                                          standing_height_m=_round(m.standing_height_m), movable_joints=movable,
                                          initial_angles=initial, randomize=randomize, target_offsets=offsets,
                                          start_configurations=configs, start_tool_positions=reached))
        bodies.append(Body(name=f"person_{variant}", kind="person", urdf=rel(written[f"person_{variant}"]), position=person_pos[variant],
                           orientation=_round(person_orn), fixed_base=True, gravity=person_spec.gravity_mps2))

    # 3c. Particles settle in their container at the nominal start pose ---------------------
    for name, ps in spec.particles.items():
        particle_sets.append(_settle_particles(rt, pc, name, ps, tool_ids, furniture_ids, start, tool_orn))

    bodies.insert(0, Body(name="robot", kind="robot", urdf=rel(written["robot"]), position=_round(base_pos), orientation=_round(base_orn),
                          fixed_base=True, gravity=spec.robot.gravity_mps2))
    return _manifest(rt, bodies, variants_out, attachments, particle_sets, arm_joints, lower, upper, movable)


def _seat_links(rt: ResolvedTask) -> list[str]:
    """Links that rest on a seat: the pelvis and thighs (waist and hip joint children)."""
    from ..person.body import JOINT_GROUPS, LINK_NAMES, JOINT_NAMES

    child = dict(zip(JOINT_NAMES, LINK_NAMES))
    joints = list(JOINT_GROUPS["waist"]) + [j for j in JOINT_NAMES if "_hip_" in j]
    return [child[j] for j in joints]


def _solve_ik(pc, robot, ee_link, pos, orn, arm_idx, ik_cols, lower, upper, rng, tries: int = 40):
    """Arm configuration reaching (pos, orn) within 1 cm and 3°, or None.

    Null-space IK over every movable joint (limits, ranges, random rest poses after the first
    try); deterministic for a given ``rng`` state.
    """
    p, c = pc.p, pc.client
    movable = [j for j in range(p.getNumJoints(robot, physicsClientId=c)) if p.getJointInfo(robot, j, physicsClientId=c)[2] != p.JOINT_FIXED]
    lo_all = [p.getJointInfo(robot, j, physicsClientId=c)[8] for j in movable]
    hi_all = [p.getJointInfo(robot, j, physicsClientId=c)[9] for j in movable]
    ranges = [max(h - l, 1e-3) for l, h in zip(lo_all, hi_all)]
    current = [p.getJointState(robot, j, physicsClientId=c)[0] for j in movable]
    for attempt in range(tries):
        rest = list(current)
        arm_rest = [0.5 * (l + u) for l, u in zip(lower, upper)] if attempt == 0 else list(rng.uniform(lower, upper))
        for col, q in zip(ik_cols, arm_rest):
            rest[col] = q
        for j, q in zip(movable, rest):
            p.resetJointState(robot, j, q, physicsClientId=c)
        q = arm_rest
        for _ in range(4):  # refine from the last solution
            sol = p.calculateInverseKinematics(robot, ee_link, pos, orn, lowerLimits=lo_all, upperLimits=hi_all,
                                               jointRanges=ranges, restPoses=rest, maxNumIterations=100,
                                               residualThreshold=1e-6, physicsClientId=c)
            q = [min(max(sol[k], l), u) for k, l, u in zip(ik_cols, lower, upper)]
            for i, v in zip(arm_idx, q):
                p.resetJointState(robot, i, v, physicsClientId=c)
        got_pos, got_orn = pc.link_pose(robot, ee_link)
        err = float(np.linalg.norm(np.subtract(got_pos, pos)))
        dot = min(1.0, abs(float(np.dot(got_orn, orn))))
        if err < 0.01 and 2 * math.acos(dot) < math.radians(3):
            return q
    return None


def _settle_particles(rt, pc, name, ps, tool_ids, furniture_ids, start, tool_orn) -> ParticleSet:
    p, c = pc.p, pc.client
    attach_ref = rt.points.get(ps.attach) or {}
    if ps.attach in tool_ids:
        holder = tool_ids[ps.attach]
        p.resetBasePositionAndOrientation(holder, start.tool_position_m, tool_orn, physicsClientId=c)
        attach_link = rt.tools[ps.attach].part.base_link
    else:
        holder = furniture_ids[ps.attach]
        attach_link = rt.furniture[ps.attach].part.base_link
    frame_pos, frame_orn = pc.link_pose(holder, pc.link_index(holder, attach_link))
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=ps.radius_m, physicsClientId=c)
    ids = []
    for i in range(ps.grid[0]):
        for j in range(ps.grid[1]):
            for k in range(ps.grid[2]):
                local = np.asarray(ps.offset_m) + ps.spacing_m * np.array([i, j, k])
                world, _ = p.multiplyTransforms(frame_pos, frame_orn, tuple(local), (0, 0, 0, 1))
                ids.append(p.createMultiBody(ps.mass_kg, shape, -1, world, physicsClientId=c))
    for _ in range(ps.settle_steps):
        p.stepSimulation(physicsClientId=c)
    inv = p.invertTransform(frame_pos, frame_orn)
    positions = []
    for b in ids:
        world, _ = p.getBasePositionAndOrientation(b, physicsClientId=c)
        local, _ = p.multiplyTransforms(inv[0], inv[1], world, (0, 0, 0, 1))
        positions.append(_round(tuple(local), 6))
        p.removeBody(b, physicsClientId=c)
    lost_link, anchor = None, (0.0, 0.0, 0.0)
    if ps.lost_beyond:
        body = ps.lost_beyond.body
        part = rt.tools[body].part if body in rt.tools else rt.furniture[body].part
        lost_link = part.base_link
        anchor = _inside_point(pc, tool_ids.get(body, furniture_ids.get(body)), lost_link)
    colors = [tuple(ps.colors_rgba[i % len(ps.colors_rgba)]) for i in range(ps.count)]
    return ParticleSet(name=name, count=ps.count, radius=ps.radius_m, mass=ps.mass_kg, attach=ps.attach, attach_link=attach_link,
                       start_positions=positions, colors=colors,
                       consumed_target=ps.consumed_at.target if ps.consumed_at else None,
                       consumed_radius=ps.consumed_at.radius_m if ps.consumed_at else 0.0,
                       lost_body=ps.lost_beyond.body if ps.lost_beyond else None, lost_link=lost_link,
                       lost_distance=ps.lost_beyond.distance_m if ps.lost_beyond else 0.0, lost_anchor=_round(anchor),
                       hit_body=ps.hit_body)


def _inside_point(pc, body: int, link_name: str) -> tuple[float, float, float]:
    """The centre of the link's first collision primitive, in the link frame: inside its geometry."""
    p, c = pc.p, pc.client
    link = pc.link_index(body, link_name)
    shapes = p.getCollisionShapeData(body, link, physicsClientId=c)
    if not shapes:
        raise SpecError.at(link_name, f"link '{link_name}' has no collision geometry to keep particles near")
    local_pos = shapes[0][5]  # in the link's inertial (COM) frame
    inertial_pos, inertial_orn = p.getDynamicsInfo(body, link, physicsClientId=c)[3:5]
    pos, _ = p.multiplyTransforms(inertial_pos, inertial_orn, local_pos, (0, 0, 0, 1))
    return tuple(pos)


def _manifest(rt, bodies, variants, attachments, particle_sets, arm_joints, lower, upper, movable) -> Manifest:
    spec = rt.spec
    robot_part = rt.robot.part
    gripper = robot_part.gripper.get(robot_part.arm_for(spec.robot.arm if spec.robot.arm != "both" else "right")[0])
    tool_part = rt.tools[next(iter(spec.tools))].part.name if spec.tools else "none"
    grip_pos = gripper.positions.get(tool_part, gripper.positions.get("none", 0.0)) if gripper else 0.0
    sizes = {name: len(g["joints"]) for name, g in rt.joint_groups.items()} | {"person.policy": len(_policy_joints(rt))}
    ctx = SizeContext(sizes)
    obs_defs = terms("observation")

    def obs_use(t) -> TermUse:
        tdef = obs_defs[t.term]
        raw = {k: (v["group"] if isinstance(v, dict) and "group" in v and "joints" in v else v) for k, v in t.params.items()}
        size_params = tdef.params.model_construct(**{k: (f"{t.params[k]['body']}.{t.params[k]['group']}" if isinstance(t.params[k], dict) and "joints" in t.params[k] else v) for k, v in raw.items()})
        return TermUse(name=t.name, term=t.term, category="observation", weight=1.0, params=t.params, size=tdef.size(size_params, ctx))

    targets = {}
    for name, t in spec.targets.items():
        ref = rt.points[name]
        targets[name] = Target(body=ref["body"], link=ref["link"], offset=_round(tuple(t.offset_m)), show_rgba=t.show_rgba)
    ground = scalar_bounds(spec.sim.ground.friction)
    gains = spec.person.control
    compliant = spec.person.control.compliant
    compliant_joints = []
    if compliant:
        for ref in compliant.joints:
            compliant_joints += rt.joint_groups[ref]["joints"]
    return Manifest(
        task=spec.name, title=spec.title, robot_name=rt.robot_name, gym_id=gym_id(spec.title, robot_part.title), input_hash="",
        sources=[display(f) for f in rt.loaded.files],
        sim=Sim(time_step=spec.sim.time_step_s, frame_skip=spec.sim.frame_skip, episode_steps=spec.sim.episode_steps,
                gravity=spec.sim.gravity_mps2, sub_steps=spec.sim.solver.sub_steps, solver_iterations=spec.sim.solver.iterations,
                ground_friction=ground),
        bodies=bodies,
        person=Person(variants=variants, policy_joints=_policy_joints(rt), position_gain=gains.position_gain, max_force=gains.max_force_nm,
                      hold_gain=0.1, hold_force=1000.0, compliant_joints=compliant_joints,
                      compliant_gain=compliant.position_gain if compliant else 0.0, compliant_force=compliant.max_force_nm if compliant else 0.0,
                      impairments=[_impairment_json(ch) for ch in spec.person.impairments.choices]),
        robot=Robot(name=rt.robot_name, title=robot_part.title, arm_joints=arm_joints, joint_lower=_round(lower), joint_upper=_round(upper),
                    links=rt.robot_links, action_scale=spec.robot.control.action_scale_rad, position_gain=spec.robot.control.position_gain,
                    max_force=spec.robot.control.max_force_nm, gripper_joints=list(gripper.joints) if gripper else [], gripper_position=grip_pos),
        tools=attachments, targets=targets, particles=particle_sets, joint_groups=rt.joint_groups | {"person.policy": {"body": "person", "group": "policy", "joints": _policy_joints(rt)}},
        observations={agent: [obs_use(t) for t in ts] for agent, ts in rt.observations.items()},
        reward=[TermUse(name=t.name, term=t.term, category=t.category, weight=t.weight, params=t.params) for t in rt.reward],
        success=Success(term=spec.success.term, aggregate=spec.success.aggregate, threshold=rt.success_threshold),
        scripted=rt.scripted,
    )


def _impairment_json(choice) -> dict[str, Any]:
    out = choice.model_dump(mode="json")
    for key, value in list(out.items()):
        if key.endswith("_deg"):
            lo, hi = scalar_bounds(getattr(choice, key))
            out[key.replace("_deg", "_rad")] = [math.radians(lo), math.radians(hi)]
            del out[key]
        elif isinstance(getattr(choice, key, None), (Uniform, float, int)) and key != "kind":
            lo, hi = scalar_bounds(getattr(choice, key))
            out[key] = [lo, hi]
    return out


def compile_task(
    spec_path: str | Path,
    robot: str | None = None,
    out_dir: str | Path | None = None,
    *,
    library: Library | None = None,
    force: bool = False,
) -> CompileResult:
    """Compile the spec at ``spec_path`` for ``robot`` into ``out_dir`` (default generated/<task>-<robot>).

    Raises :class:`SpecError` for bad input; leaves ``out_dir`` untouched unless it succeeds.
    """
    t0 = time.perf_counter()
    loaded: LoadedSpec = load_spec(spec_path)
    library = library or Library()
    rt = resolve(loaded, robot, library)
    out = Path(out_dir) if out_dir else default_out_dir(loaded.spec.name, rt.robot_name)
    ihash = input_hash(rt)
    manifest_path = out / "manifest.json"
    if not force and manifest_path.is_file():
        try:
            existing = Manifest.read(out)
        except Exception:
            existing = None
        if existing is not None and existing.input_hash == ihash and all((out / b.urdf).is_file() for b in existing.bodies):
            return CompileResult(out, existing, True, time.perf_counter() - t0)

    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-", dir=out.parent))
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it private; the artifact is an ordinary directory
    try:
        manifest = build(rt, tmp, library).model_copy(update={"input_hash": ihash})
        body_bytes = b"".join((tmp / b.urdf).read_bytes() for b in sorted(manifest.bodies, key=lambda b: b.urdf))
        manifest = manifest.model_copy(update={"content_hash": _sha(body_bytes + manifest.to_json().encode())})
        (tmp / "manifest.json").write_text(manifest.to_json())
        _replace_dir(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return CompileResult(out, manifest, False, time.perf_counter() - t0)


def _replace_dir(new: Path, out: Path) -> None:
    """Move ``new`` to ``out``, replacing any previous ``out`` only once ``new`` is complete."""
    old = None
    if out.exists():
        old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-", dir=out.parent))
        os.rmdir(old)
        os.rename(out, old)
    os.rename(new, out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)

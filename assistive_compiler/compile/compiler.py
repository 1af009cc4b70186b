"""The compiler: a resolved task → an artifact directory (URDFs + ``manifest.json``).

Steps, in order:

1. **Render** every body from its xacro template (the person once per variant, with the task's
   static joints baked into fixed joints at their posture angles; the robot with every joint the
   task does not drive welded: fingers at the task's grip, the rest at 0).
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
    Capsule,
    Container,
    Garment,
    ParticleRest,
    MarkerPoint,
    MarkerSet,
    Manifest,
    ParticleSet,
    Person,
    PersonVariant,
    Robot,
    Sim,
    StartState,
    Success,
    Target,
    TermUse,
    ToolAttachment,
)
from ..bullet import connect
from ..errors import Problem, SpecError
from ..library import PERSON_TEMPLATE_RELPATH, Library
from ..paths import display, templates_dir
from ..person.body import format_fixed_joints
from ..quat import capsule_axes
from ..resolve import ResolvedTask, resolve
from ..spec.load import LoadedSpec, load_spec
from ..spec.models import scalar_bounds
from ..terms.registry import SizeContext, terms
from .lint import lint_urdf
from .merge import merge_fixed_links, weld_joints
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


def input_hash(loaded: LoadedSpec, robot: str, library: Library) -> str:
    """sha256 over every input that can change the output, known before resolving: the spec files,
    every part file of the library, every template (ours and those beside user libraries), the
    compiler's own source, and the robot. Conservative — editing any part invalidates every
    artifact — so a cache hit never needs resolution."""
    h = hashlib.sha256(f"assistive-compiler {__version__} robot={robot}\n".encode())
    files = list(loaded.files)
    if loaded.spec.person.control.arm_limits not in ("none", "analytic") and _arm_limits_path(loaded).is_file():
        files.append(_arm_limits_path(loaded))  # a user's arm-limit network
    for root in library.roots:
        files += sorted(root.rglob("*.yaml")) + sorted((root.parent / "templates").rglob("*.xacro"))
    files += sorted(templates_dir().rglob("*.xacro")) + sorted(PACKAGE_DIR.rglob("*.py"))
    for path in files:
        h.update(str(path).encode() + b"\0" + Path(path).read_bytes() + b"\0")
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

    def __init__(self, contact_breaking_threshold: float) -> None:
        import pybullet

        self.p = pybullet
        self.client = connect(contact_breaking_threshold)

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

    def place(self, body: int, pos, orn) -> None:
        """Put a body's URDF base frame (not its centre of mass) at (pos, orn)."""
        p, c = self.p, self.client
        inertial_pos, inertial_orn = p.getDynamicsInfo(body, -1, physicsClientId=c)[3:5]
        com_pos, com_orn = p.multiplyTransforms(pos, orn, inertial_pos, inertial_orn)
        p.resetBasePositionAndOrientation(body, com_pos, com_orn, physicsClientId=c)

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
        source = lib.urdf_path(rt.robot)
        xml = absolute_mesh_paths(source.read_text(), source.parent)
        problems = lint_urdf(xml, template=display(source), static_root=True)
        if problems:
            raise SpecError([Problem(rt.robot.smap.value(("urdf",)), f"URDF refused: {pr}") for pr in problems])
        written["robot"] = urdf_dir / "robot.urdf"
        written["robot"].write_text(xml)
    else:
        emit("robot", lib.template_path(rt.robot), robot_part.template.params, rt.robot.smap.value(("template", "path")))
    robot_xml = written["robot"].read_text()
    welded = _robot_welds(rt, robot_xml)
    written["robot"].write_text(weld_joints(robot_xml, welded))
    mounted_on = spec.robot.mount_on if robot_part.mountable else None
    for name, use in _present_furniture(rt).items():
        part = rt.furniture[name].part
        params = dict(part.template.params) | (dict(part.mount_params) if name == mounted_on else {})
        params |= dict(use.params)  # the task's explicit parameters win (e.g. a mount on the person's left)
        emit(name, lib.template_path(rt.furniture[name]), params, rt.furniture[name].smap.value(("template", "path")))
    for name, use in rt.tool_uses.items():
        part = rt.tools[name].part
        params = dict(part.template.params) | ({"mass_kg": use.mass_kg} if use.mass_kg else {})
        emit(name, lib.template_path(rt.tools[name]), params, rt.tools[name].smap.value(("template", "path")))

    person = spec.person
    movable = set(person.randomize_deg) | set(rt.joint_groups.get("person.policy", {}).get("joints", []))
    movable |= set(_policy_joints(rt))
    if person.control.compliant:
        for ref in person.control.compliant.joints:
            movable |= set(rt.joint_groups[ref]["joints"])
    for choice in person.impairments.choices:  # impaired joints move (tremor) or keep their limits
        movable |= set(_impairment_joints(rt, choice))
    movable |= _observed_person_joints(rt)  # a joint a term reads keeps its joint (held at its posture)
    person_joints = [j for j in rt.person_urdf.movable_joints]
    movable_ordered = [j for j in person_joints if j in movable]
    measurements = {variant: rt.people[variant].part.measurements() for variant in person.variants}
    # Supine people settle at compile time (limp, free base, onto the furniture); their settled
    # angles are the posture, overridden by any joints_deg the spec gives.
    settled = {variant: _settle_person(rt, written, variant, measurements[variant]) for variant in person.variants} if person.placement.settle else {}
    postures: dict[str, dict[str, float]] = {}
    for i, variant in enumerate(person.variants):
        part = rt.people[variant].part
        posture = dict(settled[variant][2]) if variant in settled else {j: 0.0 for j in person_joints}
        posture |= {j: math.radians(a) for j, a in person.joints_deg.items()}
        postures[variant] = posture
        baked = {j: posture[j] for j in person_joints if j not in movable}
        args = measurements[variant].xacro_args() | {"fixed_joints": format_fixed_joints(baked), "skin_rgba": " ".join(repr(float(c)) for c in part.skin_rgba)}
        emit(f"person_{variant}", templates_dir() / PERSON_TEMPLATE_RELPATH, args, rt.loaded.smap.value(("person", "variants", i)))

    # 3. Precompute (on the unmerged bodies) -------------------------------------------------
    pc = _Precompute(rt.spec.sim.solver.contact_breaking_threshold_m)
    try:
        manifest = _precompute(rt, pc, written, out_tmp, postures, movable_ordered, measurements, mounted_on, settled)
    finally:
        pc.close()
    manifest = manifest.model_copy(update={"robot": manifest.robot.model_copy(update={"welded_joints": welded})})

    # 4. Merge each person's static links into as few rigid links as possible: a seated person
    #    with a movable head goes from 43 links to 5, which is most of a step's physics cost.
    keep = _referenced_person_links(rt)
    collision_keep, collision_pairs = person_self_collision(written[f"person_{person.variants[0]}"].read_text(), keep)
    keep |= collision_keep  # links kept so that self-collision stays exact (see person_self_collision)
    for variant in person.variants:
        path = written[f"person_{variant}"]
        merged, _frames = merge_fixed_links(path.read_text(), keep=keep)
        problems = lint_urdf(merged, template=f"merged person '{variant}'")
        if problems:  # pragma: no cover - the merge preserves validity; lint guards it
            raise SpecError([Problem(rt.loaded.smap.value(("person", "variants")), f"merged person URDF refused: {pr}") for pr in problems])
        path.write_text(merged)
    return _finish_person(rt, manifest, out_tmp, collision_pairs)


def person_self_collision(urdf_xml: str, keep: set[str]) -> tuple[set[str], list[tuple[str, str]]]:
    """Which person links collide with each other, and which links the merge must keep for that.

    ``urdf_xml`` is the unmerged person (static joints already fixed), ``keep`` the links the
    merge keeps anyway. The reference's groups (facts §3.3, ``SELF_COLLISION_GROUPS``: each arm
    and leg against the rest, never torso, head and girdles among themselves) are applied to the
    groups whose links move in the task (below a movable joint); a person whose arms and legs are
    all static (Feeding: only the head moves) gets no self-collision at all.

    Merging puts several original links into one rigid link, named after the link that survives
    (``merge_fixed_links``). A pair of surviving links collides when their names form an enabled
    pair; that is exact only if every pair of geometry-carrying links they contain agrees. Where
    one does not — a static shoulder girdle, which overlaps the upper arm and must not collide
    with it, merged into the chest that a moving arm must collide with; the stomach and hips
    merged into the chest against a moving thigh; a static upper arm merged into the chest
    while its forearm moves — the link is kept out of the merge (a link of its own on its fixed
    joint) until all agree. Returns (extra links to keep, enabled pairs of surviving link names),
    the pairs sorted and limited to links that move relative to each other and are not parent
    and child (pybullet never collides those).
    """
    import xml.etree.ElementTree as ET

    from ..person.body import SELF_COLLISION_GROUPS

    root = ET.fromstring(urdf_xml)
    parent: dict[str, tuple[str, bool]] = {}  # child link -> (parent link, joint is fixed)
    for joint in root.findall("joint"):
        parent[joint.find("child").get("link")] = (joint.find("parent").get("link"), joint.get("type") == "fixed")
    geometry = sorted(link.get("name") for link in root.findall("link") if link.find("collision") is not None)

    def chain(link: str) -> list[tuple[str, bool]]:
        """(link, its joint is fixed) from ``link`` up to (not including) the root."""
        out = []
        while link in parent:
            out.append((link, parent[link][1]))
            link = parent[link][0]
        return out

    geometry.sort(key=lambda link: (len(chain(link)), link))  # root side first: keeping a link keeps what hangs on it
    moving = {link for link in geometry if any(not fixed for _, fixed in chain(link))}
    enabled: set[tuple[str, str]] = set()
    for group in SELF_COLLISION_GROUPS.values():
        if moving & set(group.links):
            enabled |= {tuple(sorted((a, b))) for a in group.links for b in group.against if a != b}  # type: ignore[misc]
    extra: set[str] = set()
    if not enabled:
        return extra, []

    def survivor(link: str) -> str:
        while link in parent and parent[link][1] and link not in keep and link not in extra:
            link = parent[link][0]
        return link

    def rigid(a: str, b: str) -> bool:
        """No movable joint on the tree path between surviving links a and b."""
        up_a, up_b = chain(a), chain(b)
        common = {name for name, _ in up_a} & {name for name, _ in up_b}
        return all(fixed for name, fixed in up_a + up_b if name not in common)

    changed = True
    while changed:
        changed = False
        for i, a in enumerate(geometry):
            for b in geometry[i + 1:]:
                sa, sb = survivor(a), survivor(b)
                if sa == sb or rigid(sa, sb):
                    continue
                if (tuple(sorted((a, b))) in enabled) != (tuple(sorted((sa, sb))) in enabled):
                    pick = a if a != sa else b  # one of them is merged (two survivors agree by definition)
                    assert pick not in extra
                    extra.add(pick)
                    changed = True
    survivors = sorted({survivor(link) for link in geometry})
    pairs = [(a, b) for i, a in enumerate(survivors) for b in survivors[i + 1:]
             if (a, b) in enabled and not rigid(a, b) and parent.get(a, ("",))[0] != b and parent.get(b, ("",))[0] != a]
    return extra, pairs


def _finish_person(rt: ResolvedTask, manifest: Manifest, out_tmp: Path, pairs: list[tuple[str, str]]) -> Manifest:
    """The person's runtime settings that need the merged bodies or extra files: the self-collision
    pairs minus those already touching (within 1 mm) at a variant's initial pose — shapes that
    overlap at rest, such as the upper arm and the chest capsule, would otherwise push each other
    apart at every reset — and the arm-limit model (a user's .npz is copied into the artifact)."""
    update: dict[str, Any] = {}
    if pairs:
        import pybullet

        pc = _Precompute(rt.spec.sim.solver.contact_breaking_threshold_m)
        try:
            p, c = pc.p, pc.client
            touching: set[tuple[str, str]] = set()
            for variant in manifest.person.variants:
                body = manifest.body(variant.body)
                bid = p.loadURDF(str(out_tmp / body.urdf), useFixedBase=True, flags=pybullet.URDF_USE_SELF_COLLISION, physicsClientId=c)
                joints = pc.joint_index(bid)
                for name, q in variant.initial_angles.items():
                    p.resetJointState(bid, joints[name], q, physicsClientId=c)
                for a, b in pairs:
                    if p.getClosestPoints(bid, bid, 0.001, pc.link_index(bid, a), pc.link_index(bid, b), physicsClientId=c):
                        touching.add((a, b))
        finally:
            pc.close()
        update["self_collision"] = [pair for pair in pairs if pair not in touching]
    setting = rt.spec.person.control.arm_limits
    if setting not in ("none", "analytic"):
        from ..person.arm_limits import MLPArmLimits

        where = rt.loaded.smap.value(("person", "control", "arm_limits"))
        source = _arm_limits_path(rt.loaded)
        try:
            MLPArmLimits.from_npz(source)
        except ValueError as exc:
            raise SpecError([Problem(where, f"person.control.arm_limits: {exc}")]) from None
        shutil.copyfile(source, out_tmp / "arm_limits.npz")
        update |= {"arm_limits": "arm_limits.npz", "arm_limits_sha256": _sha(source.read_bytes())}
    if not update:
        return manifest
    return manifest.model_copy(update={"person": manifest.person.model_copy(update=update)})


def _arm_limits_path(loaded: LoadedSpec) -> Path:
    """The .npz that ``person.control.arm_limits`` names, relative to the spec file that says it."""
    value = loaded.spec.person.control.arm_limits
    where = loaded.smap.value(("person", "control", "arm_limits")).path
    spec_file = next((f for f in loaded.files if display(f) == where), loaded.path)
    return (Path(spec_file).parent / value).resolve()


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
    for ref in rt.points.values():
        found.update(ref.get("surface_links", ()))
    for ms in rt.markers.values():
        found.update(ms["links"])
    return found


def absolute_mesh_paths(urdf_xml: str, base: Path) -> str:
    """A URDF with every relative ``<mesh filename>`` made absolute (relative to ``base``), so it
    works from the artifact directory. ``package://`` paths are left for the lint to refuse."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(urdf_xml)
    for mesh in root.iter("mesh"):
        name = mesh.get("filename", "")
        if name and "://" not in name and not Path(name).is_absolute():
            mesh.set("filename", str((base / name).resolve()))
    return ET.tostring(root, encoding="unicode")


def _group_joints(rt: ResolvedTask, refs) -> list[str]:
    """The person joints of joint-group references (``person.policy`` included), in order, once each."""
    out: list[str] = []
    for ref in refs:
        group = _policy_joints(rt) if ref == "person.policy" else rt.joint_groups[ref]["joints"]
        out += [j for j in group if j not in out]
    return out


def _policy_joints(rt: ResolvedTask) -> list[str]:
    return _group_joints(rt, rt.spec.person.control.policy_joints)


def _set_friction(pc: _Precompute, body: int, friction: float) -> None:
    """Lateral friction of every link of ``body`` (base included)."""
    p, c = pc.p, pc.client
    for link in range(-1, p.getNumJoints(body, physicsClientId=c)):
        p.changeDynamics(body, link, lateralFriction=friction, physicsClientId=c)


def _observed_person_joints(rt: ResolvedTask) -> set[str]:
    """Person joints named by a joint group in any term's parameters (e.g. ``joint_angles`` of
    ``person.head``): they are not baked into fixed joints, so the runtime can read them."""
    out: set[str] = set()
    for term in [t for ts in rt.observations.values() for t in ts] + list(rt.reward):
        for value in term.params.values():
            if isinstance(value, dict) and value.get("body") == "person" and "joints" in value:
                out |= set(value["joints"])
    return out


def _settle_person(rt: ResolvedTask, written: dict[str, Path], variant: str, measurements) -> tuple[tuple, tuple, dict[str, float]]:
    """Drop the limp person onto the furniture (facts §2.2): every joint free and perturbed by
    U(±joint_noise_rad) around the spec's posture, a free base at the placement pose, the settle
    gravity and furniture friction, ``steps`` physics steps. Returns the settled base pose (URDF
    frame) and joint angles (rad). Deterministic per (task, robot, variant)."""
    spec = rt.spec
    settle = spec.person.placement.settle
    pc = _Precompute(rt.spec.sim.solver.contact_breaking_threshold_m)
    p, c = pc.p, pc.client
    try:
        p.setTimeStep(spec.sim.time_step_s, physicsClientId=c)
        p.setGravity(0, 0, settle.gravity_mps2, physicsClientId=c)
        p.setPhysicsEngineParameter(numSolverIterations=spec.sim.solver.iterations, numSubSteps=spec.sim.solver.sub_steps,
                                    deterministicOverlappingPairs=1, physicsClientId=c)
        p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, physicsClientId=c), physicsClientId=c)
        for name, use in _present_furniture(rt, placed_only=True).items():
            fid = pc.load(written[name], use.position_m, _quat_from_rpy(tuple(math.radians(a) for a in use.rpy_deg)), True)
            if settle.friction is not None:
                _set_friction(pc, fid, settle.friction)
        part = rt.people[variant].part
        args = measurements.xacro_args() | {"fixed_joints": "", "skin_rgba": " ".join(repr(float(v)) for v in part.skin_rgba)}
        limp = written["robot"].with_name(f".settle_{variant}.urdf")
        limp.write_text(render_template(templates_dir() / PERSON_TEMPLATE_RELPATH, args))
        placement = spec.person.placement
        orn = _quat_from_rpy(tuple(math.radians(a) for a in placement.rpy_deg))
        body = pc.load(limp, (0, 0, 0), orn, False)
        limp.unlink()
        pc.place(body, tuple(placement.position_m), orn)
        rng = np.random.default_rng(_seed(rt, variant) ^ 0x5E771E)
        joints = pc.joint_index(body)
        names = [j for j in rt.person_urdf.movable_joints]
        for name in names:
            info = rt.person_urdf.movable_joints[name]
            q = math.radians(spec.person.joints_deg.get(name, 0.0)) + rng.uniform(-settle.joint_noise_rad, settle.joint_noise_rad)
            p.resetJointState(body, joints[name], min(max(q, info.lower), info.upper), physicsClientId=c)
        idx = [joints[n] for n in names]
        p.setJointMotorControlArray(body, idx, p.VELOCITY_CONTROL, forces=[0.0] * len(idx), physicsClientId=c)
        for _ in range(settle.steps):
            p.stepSimulation(physicsClientId=c)
        pos, orn = pc.link_pose(body, -1)
        angles = {n: s[0] for n, s in zip(names, p.getJointStates(body, idx, physicsClientId=c))}
        if settle.then is not None:
            angles = _settle_stage(rt, pc, body, joints, names, angles, pos, orn)
        if not all(math.isfinite(v) for v in [*pos, *orn, *angles.values()]) or abs(pos[2]) > 10:
            raise _fail(rt, ("person", "placement", "settle"), f"person '{variant}' did not settle (the body left the scene); check placement.position_m")
        return _round(tuple(pos)), _round(tuple(orn)), {n: _round(a) for n, a in angles.items()}
    finally:
        pc.close()


def _settle_stage(rt: ResolvedTask, pc: _Precompute, body: int, joints: dict[str, int], names: list[str],
                  angles: dict[str, float], pos, orn) -> dict[str, float]:
    """The settle's second stage (``placement.settle.then``): the settled base is fixed where it lies
    and every joint held stiffly at its settled angle, except the stage's dynamic joint groups,
    which are set to the stage's ``joints_deg`` and then move under the stage's gravity and weak
    hold (the reference's arm manipulation: the right arm raised, then dropped to hang off the bed
    for 100 steps at g −9.81). Returns every joint's angle afterwards (rad)."""
    spec = rt.spec
    stage = spec.person.placement.settle.then
    p, c = pc.p, pc.client
    dynamic = _group_joints(rt, stage.dynamic)
    start = dict(angles) | {j: math.radians(a) for j, a in stage.joints_deg.items()}
    com_pos, com_orn = p.getBasePositionAndOrientation(body, physicsClientId=c)
    p.createConstraint(body, -1, -1, -1, p.JOINT_FIXED, (0, 0, 0), (0, 0, 0), com_pos, (0, 0, 0, 1), com_orn, physicsClientId=c)
    p.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0), physicsClientId=c)
    for n in names:
        p.resetJointState(body, joints[n], start[n], 0.0, physicsClientId=c)
    held = [n for n in names if n not in dynamic]
    p.setJointMotorControlArray(body, [joints[n] for n in held], p.POSITION_CONTROL, targetPositions=[start[n] for n in held],
                                forces=[1e4] * len(held), physicsClientId=c)
    if stage.hold is not None and dynamic:
        p.setJointMotorControlArray(body, [joints[n] for n in dynamic], p.POSITION_CONTROL, targetPositions=[start[n] for n in dynamic],
                                    positionGains=[stage.hold.position_gain] * len(dynamic), forces=[stage.hold.max_force_nm] * len(dynamic),
                                    physicsClientId=c)
    if stage.friction is not None:
        for bid in range(p.getNumBodies(physicsClientId=c)):
            if bid != body:
                _set_friction(pc, bid, stage.friction)
    p.setGravity(0, 0, stage.gravity_mps2, physicsClientId=c)
    for _ in range(stage.steps):
        p.stepSimulation(physicsClientId=c)
        for n in held:  # static joints stay exactly where they settled
            p.resetJointState(body, joints[n], start[n], 0.0, physicsClientId=c)
    idx = [joints[n] for n in names]
    return {n: s[0] for n, s in zip(names, p.getJointStates(body, idx, physicsClientId=c))}


def _precompute(rt, pc: _Precompute, written, out_tmp, postures, movable, measurements, mounted_on, settled) -> Manifest:
    spec = rt.spec
    p, c = pc.p, pc.client
    p.setGravity(0, 0, spec.sim.gravity_mps2, physicsClientId=c)
    p.setTimeStep(spec.sim.time_step_s, physicsClientId=c)
    rel = lambda path: str(path.relative_to(out_tmp))  # noqa: E731
    bodies: list[Body] = []

    # Furniture at its nominal pose.
    furniture_ids: dict[str, int] = {}
    for name, use in _present_furniture(rt).items():
        part = rt.furniture[name].part
        orn = _quat_from_rpy(tuple(math.radians(a) for a in use.rpy_deg))
        static = part.static if use.static is None else use.static
        furniture_ids[name] = pc.load(written[name], use.position_m, orn, True)
        bodies.append(Body(name=name, kind="furniture", urdf=rel(written[name]), position=_round(use.position_m), orientation=_round(orn),
                           fixed_base=static, gravity=None, friction=use.friction if use.friction is not None else part.friction,
                           position_noise=_round(use.position_noise_m)))

    # Person: seated on the furniture's seat surface, or at an explicit position.
    person_spec = spec.person
    person_orns = {v: settled[v][1] if v in settled else _quat_from_rpy(tuple(math.radians(a) for a in person_spec.placement.rpy_deg))
                   for v in person_spec.variants}
    person_ids: dict[str, int] = {}
    person_pos: dict[str, tuple] = {}
    for variant in person_spec.variants:
        body_name = f"person_{variant}"
        person_orn = person_orns[variant]
        probe = pc.load(written[body_name], (0, 0, 0), person_orn, True)
        if variant in settled:
            pos = settled[variant][0]
        elif person_spec.placement.seated_on:
            seat_name = person_spec.placement.seated_on
            seat_part = rt.furniture[seat_name].part
            seat_pos, _ = pc.link_pose(furniture_ids[seat_name], pc.link_index(furniture_ids[seat_name], seat_part.seat_link))
            lowest = min(p.getAABB(probe, pc.link_index(probe, link), physicsClientId=c)[0][2] for link in _seat_links(rt))
            pos = (seat_pos[0], seat_pos[1], seat_pos[2] - lowest + 0.002)
            pos = tuple(a + b for a, b in zip(pos, person_spec.placement.offset_m))
        else:
            pos = tuple(person_spec.placement.position_m)
        pc.place(probe, pos, person_orn)
        jidx = pc.joint_index(probe)
        for j in movable:
            p.resetJointState(probe, jidx[j], postures[variant][j], physicsClientId=c)
        person_ids[variant], person_pos[variant] = probe, _round(pos)

    # Robot: loaded once; its base is placed per candidate pose below.
    robot_part = rt.robot.part
    per_robot = spec.robot.per_robot.get(rt.robot_name)
    offset = per_robot.base_offset_m if per_robot and per_robot.base_offset_m else (0.0, 0.0, 0.0)
    robot_id = pc.load(written["robot"], (0, 0, 0), (0, 0, 0, 1), True)
    robot_joints = pc.joint_index(robot_id)
    arm_joints = rt.joint_groups["robot.arm"]["joints"]
    infos = {j: p.getJointInfo(robot_id, robot_joints[j], physicsClientId=c) for j in arm_joints}
    lower = [infos[j][8] for j in arm_joints]
    upper = [infos[j][9] for j in arm_joints]
    mount_pose = None
    carry: _Carried | None = None
    if mounted_on:
        fpart = rt.furniture[mounted_on].part
        mpos, morn = pc.link_pose(furniture_ids[mounted_on], pc.link_index(furniture_ids[mounted_on], fpart.mount_link))
        if spec.robot.mount_base == "search":  # loaded at the origin: the mount link's pose is its pose in the furniture frame
            carry = _Carried(pc, furniture_ids[mounted_on], tuple(mpos), tuple(morn))
        else:
            mount_pose = (tuple(a + b for a, b in zip(mpos, offset)), tuple(morn))

    # Tools and the grip transform.
    tool_ids: dict[str, int] = {}
    attachments: list[ToolAttachment] = []
    for name, use in rt.tool_uses.items():
        tpart = rt.tools[name].part
        grip = robot_part.grips[tpart.name]
        _, hand = robot_part.arm_for(use.hand)
        tool_ids[name] = pc.load(written[name], (0, 0, -10), (0, 0, 0, 1), True)
        attachments.append(ToolAttachment(body=name, parent_link=hand.tool_mount, position=_round(grip.position_m),
                                          orientation=_round(_quat_from_rpy(grip.rpy_rad)),
                                          links=dict(tpart.links) | {"base": tpart.base_link}))
        bodies.append(Body(name=name, kind="tool", urdf=rel(written[name]), position=(0.0, 0.0, 0.0), orientation=(0.0, 0.0, 0.0, 1.0),
                           fixed_base=False, gravity=use.gravity_mps2))

    # 3b. Base poses and start configurations, per person variant -----------------------------
    # One kinematic chain per acting side (a two-arm robot in a task with arm 'both' has two),
    # each with its own start pose and the tool (or garment) in its hand.
    garment_grips = {}
    for gname, g in spec.garments.items():
        grip = robot_part.grips[g.held.grip]
        garment_grips[gname] = (robot_part.arm_for(g.held.hand)[1].tool_mount, _round(tuple(grip.position_m)), _round(_quat_from_rpy(grip.rpy_rad)))
    arms: list[tuple[_ArmKinematics, Any, tuple]] = []  # (kinematics, start goal, tool orientation)
    offset_in_action = 0
    for side in rt.sides:
        real_side, arm = robot_part.arm_for(side)
        n = len(arm.joints)
        side_start = _start_for(rt, side)
        side_orn = _quat_from_rpy(tuple(math.radians(a) for a in side_start.tool_rpy_deg))
        held = [k for k, (name, use) in enumerate(rt.tool_uses.items()) if robot_part.arm_for(use.hand)[0] == real_side]
        held_garments = [garment_grips[gname][1:] for gname, g in spec.garments.items() if robot_part.arm_for(g.held.hand)[0] == real_side]
        if held:
            att = attachments[held[0]]
            inv = p.invertTransform(att.position, att.orientation)
            side_tools = {att.body: tool_ids[att.body]}
        elif held_garments:  # the start pose is the garment's held frame
            inv, side_tools = p.invertTransform(*held_garments[0]), {}
        else:
            inv, side_tools = ((0, 0, 0), (0, 0, 0, 1)), {}
        kin = _ArmKinematics(pc, robot_id, pc.link_index(robot_id, arm.tool_mount), [robot_joints[j] for j in arm.joints],
                             lower[offset_in_action:offset_in_action + n], upper[offset_in_action:offset_in_action + n],
                             inv, side_tools, list(furniture_ids.values()), arm.rest_rad)
        arms.append((kin, side_start, side_orn))
        offset_in_action += n
    arm_kin, start, tool_orn = arms[0]
    variants_out: list[PersonVariant] = []
    particle_sets: list[ParticleSet] = []
    placements: dict[str, Any] = {}
    for variant in person_spec.variants:
        for other, pid in person_ids.items():  # only this variant in the scene
            pc.place(pid, person_pos[other] if other == variant else (0, 0, -20), person_orns[other])
        rng = np.random.default_rng(_seed(rt, variant))
        goals = []
        for side, (kin, side_start, side_orn) in zip(rt.sides, arms):
            kin.person = person_ids[variant]
            what = "the start pose" if len(arms) == 1 else f"the {side} arm's start pose"
            goals.append((tuple(side_start.tool_position_m), side_orn, True, what, kin, True))
        for g in rt.base_goals:
            where = np.asarray(_point_world(pc, rt, g["point"], person_ids[variant], variant, furniture_ids, tool_ids)) + g["offset_m"]
            k = rt.sides.index(g["arm"]) if g["arm"] in rt.sides else 0
            kin, _, side_orn = arms[k]
            goals.append((tuple(where), side_orn if g["oriented"] else None, g["required"], _describe_point(g["point"]), kin, False))
        if mount_pose is not None:
            bases = [(mount_pose, len(goals), 0.0)]
            placements[variant] = {"mounted_on": mounted_on}
        else:
            bases = _search_base(rt, [a[0] for a in arms], goals, offset, rng, carry)
            placements[variant] = {"base_poses": [{"position": list(_round(b[0][0])), "yaw_rad": _round(_yaw(b[0][1])),
                                                   "goals_reached": b[1], "goals": len(goals), "jlwki": _round(b[2])} for b in bases]}
        starts: list[StartState] = []
        per_base = max(1, math.ceil(start.samples / len(bases)))
        for (base_pos, base_orn), _, _ in bases:
            arm_kin.place(base_pos, base_orn)
            if carry is not None:
                carry.place(base_pos, base_orn)
            for kin, _, _ in arms:
                kin.set_arm(kin.rest)
            for s in range(per_base):
                qs, first_goal = [], None
                for kin, side_start, side_orn in arms:
                    noise = np.zeros(3) if s == 0 else rng.uniform(-side_start.noise_m, side_start.noise_m, 3)
                    goal = tuple(np.asarray(side_start.tool_position_m) + noise)
                    q = kin.reach(goal, side_orn, rng, tries=24)
                    if q is None:
                        break
                    qs += list(q)
                    first_goal = first_goal or goal
                else:
                    starts.append(StartState(base_position=_round(base_pos), base_orientation=_round(base_orn), joints=_round(qs), tool_position=_round(first_goal)))
        if not starts:
            own = spec.robot.per_robot.get(rt.robot_name)
            where = ("robot", "per_robot", rt.robot_name, "start", "tool_position_m") if own is not None and own.start is not None else ("robot", "start", "tool_position_m")
            raise _fail(rt, where,
                        f"robot '{rt.robot_name}' cannot reach the start pose {tuple(start.tool_position_m)} (tool rpy {tuple(start.tool_rpy_deg)}°) without collision for person '{variant}'")
        m = measurements[variant]
        offsets = {}
        for tname, target in spec.targets.items():
            if rt.points.get(tname, {}).get("body") == "person":
                offsets[tname] = _round(tuple(target.offset_by_variant.get(variant, target.offset_m)))
        limbs = urdf_info(written[f"person_{variant}"].read_text()).capsules
        surfaces = {t: [_capsule(limbs, link) for link in ref["surface_links"]] for t, ref in rt.points.items() if "surface_links" in ref}
        marker_points = {name: _marker_points(limbs, ms["links"], ms["spacing_m"]) for name, ms in rt.markers.items()}
        initial = {j: _round(postures[variant][j]) for j in movable}
        randomize = {j: _round(tuple(math.radians(a) for a in person_spec.randomize_deg[j].uniform)) for j in movable if j in person_spec.randomize_deg}
        variants_out.append(PersonVariant(name=variant, body=f"person_{variant}", sex=m.sex, mass_kg=_round(m.mass_kg),
                                          standing_height_m=_round(m.standing_height_m), movable_joints=movable,
                                          initial_angles=initial, randomize=randomize, target_offsets=offsets, starts=starts,
                                          surfaces=surfaces, markers=marker_points))
        bodies.append(Body(name=f"person_{variant}", kind="person", urdf=rel(written[f"person_{variant}"]), position=person_pos[variant],
                           orientation=_round(person_orns[variant]), fixed_base=True, gravity=person_spec.gravity_mps2))
    first = variants_out[0].starts[0]
    base_pos, base_orn = first.base_position, first.base_orientation
    arm_kin.place(base_pos, base_orn)
    if carry is not None:  # the manifest's pose: under the first start's base; reset() carries it under each start's
        pos, orn = carry.place(base_pos, base_orn)
        k = next(i for i, b in enumerate(bodies) if b.name == mounted_on)
        bodies[k] = bodies[k].model_copy(update={"position": _round(pos), "orientation": _round(orn),
                                                 "carried_by_robot": (_round(carry.inv_pos), _round(carry.inv_orn))})
    for i, q in zip([i for kin, _, _ in arms for i in kin.arm_idx], first.joints):
        p.resetJointState(robot_id, i, q, physicsClientId=c)

    # 3c. Particles settle in their container at the nominal start pose ---------------------
    for name, ps in spec.particles.items():
        particle_sets.append(_settle_particles(rt, pc, name, ps, tool_ids, furniture_ids, start, tool_orn))

    bodies.insert(0, Body(name="robot", kind="robot", urdf=rel(written["robot"]), position=_round(base_pos), orientation=_round(base_orn),
                          fixed_base=True, gravity=spec.robot.gravity_mps2))
    garments = [_settle_garment(rt, name, g, out_tmp, garment_grips[name], tool_orn) for name, g in spec.garments.items()]
    return _manifest(rt, bodies, variants_out, attachments, particle_sets, arm_joints, lower, upper, movable, placements, garments)


def _settle_garment(rt: ResolvedTask, name: str, g, out_tmp: Path, grip, held_orn) -> Garment:
    """Generate a garment's mesh into the artifact (vertices in the held frame) and let it hang
    from the held frame — at the task's start orientation, away from everything — for
    ``settle.steps`` physics steps under ``settle.gravity_mps2`` in a deformable world with the
    task's time step and sub-steps. Returns its manifest entry with the settled nodes (held frame).
    Deterministic: the same inputs give the same bytes."""
    import pybullet as pb

    from ..garment import load_garment, sleeve_mesh, sleeve_node_sets, write_obj

    spec, shape, phys = rt.spec, g.shape, g.physics
    verts, faces = sleeve_mesh(shape.length_m, shape.radius_open_m, shape.radius_end_m, shape.rings, shape.segments)
    pose_q = _quat_from_rpy(tuple(math.radians(a) for a in g.held.rpy_deg))
    rot = np.asarray(pb.getMatrixFromQuaternion(pose_q)).reshape(3, 3)
    held_verts = verts @ rot.T + np.asarray(g.held.offset_m)
    obj = out_tmp / "garments" / f"{name}.obj"
    obj.parent.mkdir(exist_ok=True)
    write_obj(obj, np.round(held_verts, 6), faces, name=name)
    sets = {k: [int(i) for i in v] for k, v in sleeve_node_sets(shape.rings, shape.segments).items()}
    anchored = sets[g.held.nodes]
    c = connect(spec.sim.solver.contact_breaking_threshold_m, deformable=True)
    try:
        pb.setTimeStep(spec.sim.time_step_s, physicsClientId=c)
        pb.setPhysicsEngineParameter(numSubSteps=spec.sim.solver.sub_steps, physicsClientId=c)
        pb.setGravity(0, 0, g.settle.gravity_mps2, physicsClientId=c)
        held_pos = (0.0, 0.0, 2.0 + shape.length_m)
        sb, anchor = load_garment(pb, c, obj, held_pos, held_orn, phys.mass_kg, phys.collision_margin_m, phys.elastic_stiffness,
                                  phys.damping_stiffness, phys.bending_stiffness, phys.friction, anchored)
        for _ in range(g.settle.steps):
            pb.stepSimulation(physicsClientId=c)
        world = np.asarray(pb.getMeshData(sb, -1, flags=pb.MESH_DATA_SIMULATION_MESH, physicsClientId=c)[1], dtype=float)
    finally:
        pb.disconnect(c)
    inv_rot = np.asarray(pb.getMatrixFromQuaternion(held_orn)).reshape(3, 3).T
    local = (world - np.asarray(held_pos)) @ inv_rot.T
    if not np.all(np.isfinite(local)) or np.abs(local).max() > 5 * (shape.length_m + shape.radius_open_m):
        raise _fail(rt, ("garments", name, "physics"), f"garment '{name}' blew up while settling (nodes left the scene): the springs are "
                    f"integrated explicitly, so raise sim.solver.sub_steps (now {spec.sim.solver.sub_steps}) or lower physics.elastic_stiffness")
    parent, gpos, gorn = grip
    return Garment(name=name, obj=str(obj.relative_to(out_tmp)), parent_link=parent, grip_position=gpos, grip_orientation=gorn,
                   anchored=anchored, node_sets=sets, nodes_in_held=[_round(tuple(v)) for v in local], mass=phys.mass_kg,
                   collision_margin=phys.collision_margin_m, elastic_stiffness=phys.elastic_stiffness, damping_stiffness=phys.damping_stiffness,
                   bending_stiffness=phys.bending_stiffness, friction=phys.friction,
                   collides_with=list(g.collides_with) if g.collides_with is not None else None, rgba=tuple(g.rgba))


def _capsule(limbs: dict, link: str) -> Capsule:
    cap = limbs[link]
    return Capsule(link=link, start=_round(cap.start), end=_round(cap.end), radius=_round(cap.radius))


def _marker_points(limbs: dict, links: list[str], spacing: float) -> list[MarkerPoint]:
    """The reference's capsule_points: on each limb, int(L/spacing) rings at L·(i+1)/(n+1) from the
    joint end, each with int(2πr/spacing) points spacing/r radians apart (male arm: 81 + 48)."""
    out: list[MarkerPoint] = []
    for link in links:
        cap = limbs[link]
        start, r = np.asarray(cap.start), cap.radius
        length, axis, u, v = capsule_axes(cap.start, cap.end)
        rings, per_ring = int(length / spacing), int(2 * math.pi * r / spacing)
        for i in range(rings):
            centre = start + axis * length * (i + 1) / (rings + 1)
            for k in range(per_ring):
                a = k * spacing / r
                out.append(MarkerPoint(link=link, offset=_round(tuple(centre + r * (math.cos(a) * u + math.sin(a) * v)))))
    return out


def _present_furniture(rt: ResolvedTask, placed_only: bool = False) -> dict[str, Any]:
    """The scene's furniture for this robot: only_when_mounted pieces only under a mounted robot;
    with ``placed_only`` also without one carried under a searched base (its pose is not known yet)."""
    spec = rt.spec
    mounted_on = spec.robot.mount_on if rt.robot.part.mountable else None
    carried = mounted_on if spec.robot.mount_base == "search" else None
    return {name: use for name, use in spec.scene.furniture.items()
            if (not use.only_when_mounted or name == mounted_on) and not (placed_only and name == carried)}


def _seat_links(rt: ResolvedTask) -> list[str]:
    """Links that rest on a seat: the pelvis and thighs (waist and hip joint children)."""
    from ..person.body import JOINT_GROUPS, LINK_NAMES, JOINT_NAMES

    child = dict(zip(JOINT_NAMES, LINK_NAMES))
    joints = list(JOINT_GROUPS["waist"]) + [j for j in JOINT_NAMES if "_hip_" in j]
    return [child[j] for j in joints]


def _seed(rt: ResolvedTask, variant: str) -> int:
    """A deterministic seed per (task, robot, variant) for compile-time sampling."""
    digest = hashlib.sha256(f"{rt.spec.name}/{rt.robot_name}/{variant}".encode()).digest()
    return int.from_bytes(digest[:4], "little")


def _yaw(orn) -> float:
    x, y, z, w = orn
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def _describe_point(ref: dict) -> str:
    return f"target '{ref['target']}'" if "target" in ref else f"{ref['body']}.{ref['link']}"


def _point_world(pc, rt, ref, person_id, variant, furniture_ids, tool_ids) -> tuple[float, float, float]:
    """World position of a normalised point reference in the compile-time scene."""
    if "target" in ref:
        target = rt.spec.targets[ref["target"]]
        base = rt.points[ref["target"]]
        offset = target.offset_by_variant.get(variant, target.offset_m)
    else:
        base, offset = ref, (0.0, 0.0, 0.0)
    body = {"person": person_id} | furniture_ids | tool_ids
    bid = body[base["body"]]
    pos, orn = pc.link_pose(bid, pc.link_index(bid, base["link"]))
    return tuple(pc.p.multiplyTransforms(pos, orn, tuple(offset), (0, 0, 0, 1))[0])


class _ArmKinematics:
    """IK, collision checks and JLWKI for one arm in the compile-time world."""

    def __init__(self, pc, robot, ee_link, arm_idx, lower, upper, tool_from_ee, tool_ids, obstacles, rest):
        p, c = pc.p, pc.client
        self.pc, self.robot, self.ee_link, self.arm_idx = pc, robot, ee_link, arm_idx
        self.lower, self.upper = lower, upper
        self.tool_inv = tool_from_ee  # inverse grip: tool frame -> end-effector frame
        self.tool_ids, self.obstacles = tool_ids, obstacles
        self.person: int | None = None
        self.rest = rest or [0.0] * len(arm_idx)
        self.movable = [j for j in range(p.getNumJoints(robot, physicsClientId=c)) if p.getJointInfo(robot, j, physicsClientId=c)[2] != p.JOINT_FIXED]
        self.lo_all = [p.getJointInfo(robot, j, physicsClientId=c)[8] for j in self.movable]
        self.hi_all = [p.getJointInfo(robot, j, physicsClientId=c)[9] for j in self.movable]
        self.ranges = [max(h - l, 1e-3) for l, h in zip(self.lo_all, self.hi_all)]
        self.cols = [self.movable.index(i) for i in arm_idx]

    def place(self, pos, orn) -> None:
        self.pc.place(self.robot, pos, orn)

    def set_arm(self, q) -> None:
        for i, v in zip(self.arm_idx, q):
            self.pc.p.resetJointState(self.robot, i, v, physicsClientId=self.pc.client)

    def reach(self, tool_pos, tool_orn, rng, tries: int = 2, tool_may_touch: bool = False):
        """Arm configuration putting the tool at ``tool_pos`` (with ``tool_orn`` unless None) within
        1 cm (and 3°), the arm free of collisions with person and furniture, and the tool too unless
        ``tool_may_touch`` (a goal at the mouth puts the spoon against the face); None if none found."""
        p, c = self.pc.p, self.pc.client
        orn = tool_orn if tool_orn is not None else (0, 0, 0, 1)
        ee_pos, ee_orn = p.multiplyTransforms(tool_pos, orn, *self.tool_inv)
        for attempt in range(tries):
            arm_rest = list(self.rest) if attempt == 0 else list(rng.uniform(self.lower, self.upper))
            rest = [p.getJointState(self.robot, j, physicsClientId=c)[0] for j in self.movable]
            for col, q in zip(self.cols, arm_rest):
                rest[col] = q
            self.set_arm(arm_rest)
            q = arm_rest
            for _ in range(4):  # refine from the last solution
                kwargs = dict(lowerLimits=self.lo_all, upperLimits=self.hi_all, jointRanges=self.ranges, restPoses=rest,
                              maxNumIterations=100, residualThreshold=1e-6, physicsClientId=c)
                sol = (p.calculateInverseKinematics(self.robot, self.ee_link, ee_pos, ee_orn, **kwargs) if tool_orn is not None
                       else p.calculateInverseKinematics(self.robot, self.ee_link, ee_pos, **kwargs))
                q = [min(max(sol[k], l), u) for k, l, u in zip(self.cols, self.lower, self.upper)]
                self.set_arm(q)
            got_pos, got_orn = self.pc.link_pose(self.robot, self.ee_link)
            if np.linalg.norm(np.subtract(got_pos, ee_pos)) >= 0.01:
                continue
            if tool_orn is not None and 2 * math.acos(min(1.0, abs(float(np.dot(got_orn, ee_orn))))) >= math.radians(3):
                continue
            if self.collides(tool_pos, orn, check_tool=not tool_may_touch):
                continue
            return q
        return None

    def collides(self, tool_pos, tool_orn, check_tool: bool = True) -> bool:
        touching = self.pc.touching
        if any(touching(self.robot, o) for o in self.obstacles) or (self.person is not None and touching(self.robot, self.person)):
            return True
        for tid in self.tool_ids.values() if check_tool else ():
            self.pc.place(tid, tool_pos, tool_orn)
            if self.person is not None and touching(tid, self.person):
                return True
        return False

    def jlwki(self, q) -> float:
        """Joint-limit-weighted kinematic isotropy at ``q`` (facts §5: φ = 0.5, λ = 0.05)."""
        p, c = self.pc.p, self.pc.client
        all_q = [p.getJointState(self.robot, j, physicsClientId=c)[0] for j in self.movable]
        zeros = [0.0] * len(self.movable)
        lin, ang = p.calculateJacobian(self.robot, self.ee_link, [0, 0, 0], all_q, zeros, zeros, physicsClientId=c)
        J = np.vstack([np.asarray(lin)[:, self.cols], np.asarray(ang)[:, self.cols]])
        w = []
        for qi, l, u in zip(q, self.lower, self.upper):
            qr = (u - l) / 2
            w.append(max(0.001, 1 - 0.5 ** ((qr - abs(qr - qi + l)) / (0.05 * qr) + 1)))
        M = J @ np.diag(w) @ J.T
        return float(max(np.linalg.det(M), 0.0) ** (1 / 6) / (np.trace(M) / 6))


class _Carried:
    """Furniture carried under a robot whose base is searched (robot.mount_base: search): its
    mount link (pose ``mount_pos``/``mount_orn`` in the furniture frame, m) lies on the base frame."""

    def __init__(self, pc, body: int, mount_pos, mount_orn):
        self.pc, self.body, self.height = pc, body, float(mount_pos[2])
        self.inv_pos, self.inv_orn = pc.p.invertTransform(mount_pos, mount_orn)  # furniture frame in the base frame

    def place(self, base_pos, base_orn) -> tuple[tuple, tuple]:
        """Put the furniture under a base pose (world); returns its frame's world pose."""
        pos, orn = self.pc.p.multiplyTransforms(base_pos, base_orn, self.inv_pos, self.inv_orn)
        self.pc.place(self.body, pos, orn)
        return tuple(pos), tuple(orn)


def _search_base(rt: ResolvedTask, arms: list, goals, offset, rng, carry: _Carried | None = None):
    """The paper's base-pose search, bounded: exactly ``attempts`` samples; the ``keep`` best by
    (goals reached, Σ JLWKI), each reaching every required goal. ``goals`` are (position,
    orientation or None, required, description, the arm's kinematics, is a start pose); each arm
    starts from its rest pose. Raises with the goal that no sampled pose reached. With ``carry`` the base sits at the carried furniture's mount height and
    the furniture moves under every sampled base; a pose where it touches the person or other
    furniture is rejected."""
    search = rt.spec.robot.base_search
    arm = arms[0]
    anchor = np.asarray(search.origin_m[:2]) + np.asarray(offset[:2])
    z = (carry.height if carry is not None else rt.robot.part.base_height_m) + (offset[2] if len(offset) > 2 else 0.0)
    found = []
    required_misses = np.zeros(len(goals), dtype=int)
    for _ in range(search.attempts):
        xy = anchor + [rng.uniform(*search.x_range_m), rng.uniform(*search.y_range_m)]
        yaw = math.radians(search.yaw_deg + rng.uniform(-search.yaw_noise_deg, search.yaw_noise_deg))
        pos, orn = (float(xy[0]), float(xy[1]), float(z)), _quat_from_rpy((0.0, 0.0, yaw))
        arm.place(pos, orn)
        for a in arms:
            a.set_arm(a.rest)
        if carry is not None:
            carry.place(pos, orn)
            if any(arm.pc.touching(carry.body, o) for o in arm.obstacles if o != carry.body) or arm.pc.touching(carry.body, arm.person):
                continue
        # The base must clear the scene at the arm's rest pose; its own carried mount is checked per IK solution
        # only (a folded arm may rest against the mount's top, which says nothing about the base pose).
        if any(arm.pc.touching(arm.robot, o) for o in arm.obstacles if carry is None or o != carry.body) or arm.pc.touching(arm.robot, arm.person):
            continue
        reached, score, ok = 0, 0.0, True
        for k, (gpos, gorn, required, _name, kin, is_start) in enumerate(goals):
            q = kin.reach(gpos, gorn, rng, tries=2, tool_may_touch=not is_start)
            if q is None:
                if required:
                    required_misses[k] += 1
                    ok = False
                    break
                continue
            reached += 1
            score += kin.jlwki(q)
        if ok:
            found.append(((pos, orn), reached, score))
    if not found:
        worst = int(np.argmax(required_misses))
        raise _fail(rt, ("robot", "base_search"), f"robot '{rt.robot_name}' reaches {goals[worst][3]} from none of {search.attempts} sampled base poses (set robot.per_robot.{rt.robot_name}.base_offset_m or widen base_search)")
    found.sort(key=lambda f: (-f[1], -f[2]))
    return found[: search.keep]


def _start_for(rt: ResolvedTask, side: str):
    """The start pose of the acting side's tool: the left arm of a two-arm robot acting with both
    arms starts at robot.start_left; the right (or only) arm at per_robot.<robot>.start, else robot.start."""
    role = rt.spec.robot
    if side == "left" and len(rt.sides) > 1:
        if role.start_left is None:
            raise _fail(rt, ("robot", "arm"), f"robot '{rt.robot_name}' acts with both arms here; give robot.start_left, the left arm's start pose")
        return role.start_left
    own = role.per_robot.get(rt.robot_name)
    return own.start if own is not None and own.start is not None else role.start


def _settle_particles(rt, pc, name, ps, tool_ids, furniture_ids, start, tool_orn) -> ParticleSet:
    p, c = pc.p, pc.client
    if ps.attach in tool_ids:
        holder = tool_ids[ps.attach]
        pc.place(holder, start.tool_position_m, tool_orn)
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
                       hit_body=ps.hit_body, outside_of=_container(rt, ps.consumed_at.outside_of if ps.consumed_at else None),
                       rest=None if ps.rest is None else ParticleRest(container=_container(rt, ps.rest.container),
                                                                      max_tilt=math.radians(ps.rest.max_tilt_deg), max_speed=ps.rest.max_speed_mps))


def _container(rt: ResolvedTask, tool: str | None) -> Container | None:
    if tool is None:
        return None
    part = rt.tools[tool].part
    return Container(body=tool, link=part.base_link, radius=part.container.radius_m, height=part.container.height_m)


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


def _robot_welds(rt: ResolvedTask, urdf_xml: str) -> dict[str, float]:
    """Every moving robot joint the task does not drive, and the value it keeps all episode:
    fingers at the task's grip (:func:`_gripper`), anything else (an idle arm, a head, finger
    tips) at 0; both clamped into the joint's limits, where the limit would hold it. They are
    welded (made fixed joints) in the artifact's URDF: Bullet builds a motor row for every moving
    joint every physics step, and each row costs in proportion to the robot's joint count, so a
    Jaco's six finger joints cost about a seventh of a Scratch Itch step while holding still."""
    driven = set(rt.joint_groups["robot.arm"]["joints"])
    finger_joints, grip = _gripper(rt)
    held = dict(zip(finger_joints, grip))
    welds: dict[str, float] = {}
    for name, joint in urdf_info(urdf_xml).joints.items():
        if joint.type in ("revolute", "continuous", "prismatic") and name not in driven:
            value = held.get(name, 0.0)
            if joint.lower is not None and joint.upper is not None and joint.lower <= joint.upper:
                value = min(max(value, joint.lower), joint.upper)
            welds[name] = value
    return welds


def _gripper(rt: ResolvedTask) -> tuple[list[str], list[float]]:
    """The acting hands' finger joints and their positions for the tool each holds (or 'none')."""
    robot_part = rt.robot.part
    joints: list[str] = []
    positions: list[float] = []
    for side in rt.sides:
        real_side = robot_part.arm_for(side)[0]
        gripper = robot_part.gripper.get(real_side)
        held = [use.part for use in rt.tool_uses.values() if robot_part.arm_for(use.hand)[0] == real_side]
        if not held and len(rt.sides) == 1 and rt.tool_uses:
            held = [next(iter(rt.tool_uses.values())).part]
        tool_part = held[0] if held else "none"
        garments = [g.held.grip for g in rt.spec.garments.values() if robot_part.arm_for(g.held.hand)[0] == real_side]
        if garments:  # the hand holds a garment: its grip's finger positions, else the empty hand's
            tool_part = garments[0]
        grip_pos = gripper.positions.get(tool_part, gripper.positions.get("none", 0.0)) if gripper else 0.0
        n_fingers = len(gripper.joints) if gripper else 0
        grip_pos = [float(v) for v in grip_pos] if isinstance(grip_pos, list) else [float(grip_pos)] * n_fingers
        if len(grip_pos) != n_fingers:
            raise _fail(rt, ("tools",), f"robot '{rt.robot_name}' gives {len(grip_pos)} finger positions for '{tool_part}' but has {n_fingers} finger joints")
        joints += list(gripper.joints) if gripper else []
        positions += grip_pos
    return joints, positions


def _manifest(rt, bodies, variants, attachments, particle_sets, arm_joints, lower, upper, movable, placements, garments=()) -> Manifest:
    spec = rt.spec
    robot_part = rt.robot.part
    finger_joints, grip_pos = _gripper(rt)
    control = spec.robot.control
    chosen = {field: getattr(control, field) for field in ("position_gain", "max_force_nm")}
    for field in chosen:  # the task's explicit value, else the robot's default, else the spec default
        own = getattr(robot_part.control, field)
        if field not in control.model_fields_set and own is not None:
            chosen[field] = own
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
        targets[name] = Target(body=ref["body"], link=ref["link"], offset=_round(tuple(t.offset_m)), show_rgba=t.show_rgba,
                               surface="surface_links" in ref)
    markers = [MarkerSet(name=name, tool=ms["tool"]["body"], tool_link=ms["tool"]["link"], radius=ms["radius_m"],
                         show_rgba=ms["show_rgba"]) for name, ms in rt.markers.items()]
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
                contact_breaking_threshold=spec.sim.solver.contact_breaking_threshold_m,
                ground_friction=ground),
        bodies=bodies,
        person=Person(variants=variants, policy_joints=_policy_joints(rt), position_gain=gains.position_gain, max_force=gains.max_force_nm,
                      hold_gain=0.1, hold_force=1000.0, compliant_joints=compliant_joints,
                      compliant_gain=compliant.position_gain if compliant else 0.0, compliant_force=compliant.max_force_nm if compliant else 0.0,
                      impairments=[_impairment_json(rt, ch) for ch in spec.person.impairments.choices],
                      action_scale=gains.action_scale_rad, arm_limits=gains.arm_limits),
        robot=Robot(name=rt.robot_name, title=robot_part.title, arm_joints=arm_joints, joint_lower=_round(lower), joint_upper=_round(upper),
                    links=rt.robot_links, action_scale=control.action_scale_rad, position_gain=chosen["position_gain"],
                    max_force=chosen["max_force_nm"], gripper_joints=finger_joints, gripper_position=grip_pos,
                    placement=placements),
        tools=attachments, targets=targets, particles=particle_sets, markers=markers, joint_groups=rt.joint_groups | {"person.policy": {"body": "person", "group": "policy", "joints": _policy_joints(rt)}},
        observations={agent: [obs_use(t) for t in ts] for agent, ts in rt.observations.items()},
        reward=[TermUse(name=t.name, term=t.term, category=t.category, weight=t.weight, params=t.params) for t in rt.reward],
        success=Success(term=spec.success.term, aggregate=spec.success.aggregate, threshold=rt.success_threshold,
                        fraction_of=spec.success.relative_to if spec.success.relative_to in rt.markers else None),
        garments=list(garments),
        scripted=rt.scripted,
    )


def _impairment_joints(rt: ResolvedTask, choice) -> list[str]:
    """The person joints an impairment choice names (joint-group references resolved)."""
    return _group_joints(rt, getattr(choice, "joints", []))


def _impairment_json(rt: ResolvedTask, choice) -> dict[str, Any]:
    """An impairment choice for the runtime: ranges as [low, high] (angles in radians), joints by
    URDF name, and each joint's pose-independent limits (for limited range of motion)."""
    out: dict[str, Any] = {"kind": choice.kind}
    for key in ("amplitude_deg", "strength", "scale"):
        if hasattr(choice, key):
            lo, hi = scalar_bounds(getattr(choice, key))
            if key.endswith("_deg"):
                out[key.replace("_deg", "_rad")] = [math.radians(lo), math.radians(hi)]
            else:
                out[key] = [lo, hi]
    joints = _impairment_joints(rt, choice)
    if joints:
        movable = rt.person_urdf.movable_joints
        out["joints"] = joints
        out["limits"] = {j: [movable[j].lower, movable[j].upper] for j in joints}
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
    robot = robot or loaded.spec.robot.default
    out = Path(out_dir) if out_dir else default_out_dir(loaded.spec.name, robot)
    ihash = input_hash(loaded, robot, library)
    manifest_path = out / "manifest.json"
    if not force and manifest_path.is_file():
        try:
            existing = Manifest.read(out)
        except Exception:
            existing = None
        if existing is not None and existing.input_hash == ihash and all((out / b.urdf).is_file() for b in existing.bodies):
            return CompileResult(out, existing, True, time.perf_counter() - t0)

    rt = resolve(loaded, robot, library)
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

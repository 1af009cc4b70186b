"""Stage 1: emit the scene's URDFs from their templates (render, lint, write).

:func:`emit_props` takes a resolved task, the artifact's ``urdf/`` directory and the library, and
writes the robot (every joint the task does not drive welded: :mod:`.weld`), the present
furniture and the tools; it returns an :class:`EmittedScene`. :func:`emit_people` then writes one
person per variant, the joints the task never moves baked into fixed joints at the posture
(rad) — which, for a supine person, the settle (:mod:`.placement.settle_person`) decides, so it
runs between the two. A URDF the lint refuses raises a :class:`SpecError` located at the part's
template line; nothing else is checked here."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import Problem, SpecError
from ..library import PERSON_TEMPLATE_RELPATH, Library
from ..paths import display, templates_dir
from ..person.body import format_fixed_joints
from ..resolve import ResolvedTask
from ..templates import expand_template
from .lint import lint_urdf
from .task import impairment_joints, mounted_on, observed_person_joints, policy_joints, present_furniture
from .weld import robot_welds, weld_joints


@dataclass
class EmittedScene:
    """The URDFs written so far and the choices they embody."""

    urdf_dir: Path
    #: Body name ("robot", furniture and tool names, ``person_<variant>``) -> its URDF path.
    written: dict[str, Path]
    #: Robot joints made fixed, and their values (rad or m).
    welded: dict[str, float] = field(default_factory=dict)
    #: Person joints kept movable, in URDF order.
    movable: list[str] = field(default_factory=list)
    #: Person variant -> its body measurements.
    measurements: dict[str, Any] = field(default_factory=dict)
    #: Person variant -> every person joint's posture angle (rad); set by :func:`emit_people`.
    postures: dict[str, dict[str, float]] = field(default_factory=dict)
    #: Person variant -> settled (base position, base orientation, joint angles) of a supine
    #: person (:mod:`.placement.settle_person`); set by :func:`emit_people`, empty without a settle.
    settled: dict[str, tuple] = field(default_factory=dict)


def emit_body(scene: EmittedScene, body_name: str, template: Path, params: dict[str, Any], where) -> Path:
    """Render, lint and write one body; a refusal is located at ``where`` (the part's template line)."""
    xml = expand_template(template, params)
    problems = lint_urdf(xml, template=display(template))
    if problems:
        raise SpecError([Problem(where, f"generated URDF refused: {pr}") for pr in problems])
    path = scene.urdf_dir / f"{body_name}.urdf"
    path.write_text(xml)
    scene.written[body_name] = path
    return path


def emit_props(rt: ResolvedTask, urdf_dir: Path, lib: Library) -> EmittedScene:
    """Write the robot (welded), the present furniture and the tools into ``urdf_dir`` (created);
    the scene also records the person joints that stay movable and each variant's measurements."""
    spec = rt.spec
    urdf_dir.mkdir(parents=True)
    scene = EmittedScene(urdf_dir, {})
    robot_xml = _emit_robot(rt, scene, lib)
    scene.welded = robot_welds(rt, robot_xml)
    scene.written["robot"].write_text(weld_joints(robot_xml, scene.welded))
    mount = mounted_on(rt)
    for name, use in present_furniture(rt).items():
        part = rt.furniture[name].part
        params = dict(part.template.params) | (dict(part.mount_params) if name == mount else {})
        params |= dict(use.params)  # the task's explicit parameters win (e.g. a mount on the person's left)
        emit_body(
            scene,
            name,
            lib.template_path(rt.furniture[name]),
            params,
            rt.furniture[name].smap.value(("template", "path")),
        )
    for name, use in rt.tool_uses.items():
        part = rt.tools[name].part
        params = dict(part.template.params) | ({"mass_kg": use.mass_kg} if use.mass_kg else {})
        emit_body(
            scene, name, lib.template_path(rt.tools[name]), params, rt.tools[name].smap.value(("template", "path"))
        )
    scene.movable = _movable_person_joints(rt)
    scene.measurements = {variant: rt.people[variant].part.measurements() for variant in spec.person.variants}
    return scene


def _emit_robot(rt: ResolvedTask, scene: EmittedScene, lib: Library) -> str:
    """Write the robot as rendered (or, brought as a URDF, with absolute mesh paths); returns its XML."""
    robot_part = rt.robot.part
    if robot_part.template is None:
        source = lib.urdf_path(rt.robot)
        xml = absolute_mesh_paths(source.read_text(), source.parent)
        problems = lint_urdf(xml, template=display(source), static_root=True)
        if problems:
            raise SpecError([Problem(rt.robot.smap.value(("urdf",)), f"URDF refused: {pr}") for pr in problems])
        scene.written["robot"] = scene.urdf_dir / "robot.urdf"
        scene.written["robot"].write_text(xml)
    else:
        emit_body(
            scene,
            "robot",
            lib.template_path(rt.robot),
            robot_part.template.params,
            rt.robot.smap.value(("template", "path")),
        )
    return scene.written["robot"].read_text()


def _movable_person_joints(rt: ResolvedTask) -> list[str]:
    """Person joints that keep a joint of their own (URDF order): randomised, policy-driven,
    compliant, impaired (tremor moves them; limits need them) and observed ones."""
    person = rt.spec.person
    movable = set(person.randomize_deg) | set(policy_joints(rt))
    if person.control.compliant:
        for ref in person.control.compliant.joints:
            movable |= set(rt.joint_groups[ref].joints)
    for choice in person.impairments.choices:  # impaired joints move (tremor) or keep their limits
        movable |= set(impairment_joints(rt, choice))
    movable |= observed_person_joints(rt)  # a joint a term reads keeps its joint (held at its posture)
    return [j for j in rt.person_urdf.movable_joints if j in movable]


def emit_people(rt: ResolvedTask, scene: EmittedScene, settled: dict[str, tuple]) -> None:
    """Write ``person_<variant>.urdf`` for every variant and record its posture: the settled angles
    (``settled``: variant -> (pos, orn, angles), for supine people) else 0, overridden by the
    spec's ``joints_deg``; every joint not in ``scene.movable`` is baked at its posture angle."""
    person = rt.spec.person
    person_joints = list(rt.person_urdf.movable_joints)
    scene.settled = settled
    for i, variant in enumerate(person.variants):
        part = rt.people[variant].part
        posture = dict(settled[variant][2]) if variant in settled else {j: 0.0 for j in person_joints}
        posture |= {j: math.radians(a) for j, a in person.joints_deg.items()}
        scene.postures[variant] = posture
        baked = {j: posture[j] for j in person_joints if j not in scene.movable}
        args = person_xacro_args(scene.measurements[variant], part, format_fixed_joints(baked))
        emit_body(
            scene,
            f"person_{variant}",
            templates_dir() / PERSON_TEMPLATE_RELPATH,
            args,
            rt.loaded.smap.value(("person", "variants", i)),
        )


def person_xacro_args(measurements, part, fixed_joints: str) -> dict[str, Any]:
    """The person template's arguments: body measurements, the fixed joints' spec, the skin colour."""
    return measurements.xacro_args() | {
        "fixed_joints": fixed_joints,
        "skin_rgba": " ".join(repr(float(c)) for c in part.skin_rgba),
    }


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

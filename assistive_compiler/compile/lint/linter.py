"""The lint's element checks (rules a–g of :mod:`assistive_compiler.compile.lint`): finite
numbers, inertials, shapes and meshes of every link; type, limits and axis of every joint. The
tree (rule h) is :mod:`.tree`. :class:`Linter` collects :class:`~.problems.LintProblem`s in
document order."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .numbers import fmt, fmt_derived, number, parse_numbers, vec
from .problems import LintProblem
from .tree import lint_tree

#: Joint types a generated scene may use.
MOVABLE_LIMITED = ("revolute", "prismatic")
ALLOWED_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed")
KNOWN_JOINT_TYPES = ALLOWED_JOINT_TYPES + ("floating", "planar")
ALLOWED_GEOMETRY = ("box", "cylinder", "sphere", "mesh")
CAPSULE_HINT = "write a capsule as a cylinder plus two spheres (capsule_shapes in templates/common/shapes.xacro)"
AXIS_TOLERANCE = 1e-6
TRIANGLE_TOLERANCE = 1e-9
INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")

# Numeric attributes of URDF elements, with how many numbers each holds. Used to check that
# every number in the document is finite (rule a).
_NUMERIC_ATTRIBUTES: dict[str, dict[str, int]] = {
    "origin": {"xyz": 3, "rpy": 3},
    "axis": {"xyz": 3},
    "mass": {"value": 1},
    "inertia": {key: 1 for key in INERTIA_KEYS},
    "box": {"size": 3},
    "cylinder": {"radius": 1, "length": 1},
    "sphere": {"radius": 1},
    "capsule": {"radius": 1, "length": 1},
    "mesh": {"scale": 3},
    "limit": {"lower": 1, "upper": 1, "effort": 1, "velocity": 1},
    "dynamics": {"damping": 1, "friction": 1},
    "safety_controller": {
        "soft_lower_limit": 1,
        "soft_upper_limit": 1,
        "k_position": 1,
        "k_velocity": 1,
    },
    "mimic": {"multiplier": 1, "offset": 1},
    "calibration": {"rising": 1, "falling": 1},
    "color": {"rgba": 4},
}


class Linter:
    def __init__(
        self,
        template: str,
        base_dir: Path | None,
        require_collision: Callable[[str], bool] | None,
        static_root: bool = False,
    ) -> None:
        self.static_root = static_root
        self.template = template
        self.base_dir = base_dir
        self.require_collision = require_collision
        self.problems: list[LintProblem] = []
        # Structure faults known to crash PyBullet 3.2.7's loadURDF (segmentation fault).
        self.crash_prone: list[LintProblem] = []

    def add(self, element: str, message: str, *, crash_prone: bool = False) -> None:
        problem = LintProblem(self.template, element, message)
        self.problems.append(problem)
        if crash_prone:
            self.crash_prone.append(problem)

    # -- entry -------------------------------------------------------------------------

    def run(self, urdf_xml: str) -> list[LintProblem]:
        try:
            root = ET.fromstring(urdf_xml)
        except (ET.ParseError, ValueError) as exc:
            self.add("document", f"is not well-formed XML ({exc}); expected a URDF document")
            return self.problems
        if root.tag != "robot":
            self.add("document", f"root element is <{root.tag}>; expected <robot>")
            return self.problems

        links = root.findall("link")
        joints = root.findall("joint")
        children = {c.get("link") for j in joints for c in j.findall("child")}
        self.roots = {link.get("name") for link in links} - children
        for index, link in enumerate(links, start=1):
            self.lint_link(link, self.label("link", link, index))
        for index, joint in enumerate(joints, start=1):
            self.lint_joint(joint, self.label("joint", joint, index))
        for index, material in enumerate(root.findall("material"), start=1):
            self.check_finite(material, self.label("material", material, index))
        lint_tree(self, root, links, joints)
        return self.problems

    @staticmethod
    def label(kind: str, elem: ET.Element, index: int) -> str:
        name = elem.get("name")
        return f"{kind} '{name}'" if name else f"{kind} #{index} (unnamed)"

    # -- rule a: finite numbers ---------------------------------------------------------

    def check_finite(self, elem: ET.Element, owner: str, where: str = "") -> None:
        """Report every numeric attribute under ``elem`` that is not the right count of
        finite numbers. ``where`` prefixes messages for elements inside visual/collision."""
        for attr, count in _NUMERIC_ATTRIBUTES.get(elem.tag, {}).items():
            text = elem.get(attr)
            if text is not None and parse_numbers(text, count) is None:
                expected = "a finite number" if count == 1 else f"{count} finite numbers"
                self.add(owner, f"{where}<{elem.tag} {attr}> is {text!r}; expected {expected}")
        for child in elem:
            self.check_finite(child, owner, where)

    # -- links --------------------------------------------------------------------------

    def lint_link(self, link: ET.Element, owner: str) -> None:
        # Numbers outside visual/collision (inertial, ...) are checked here; those inside are
        # checked with a "visual 1: " prefix by lint_shape.
        for child in link:
            if child.tag not in ("visual", "collision"):
                self.check_finite(child, owner)
        if not (self.static_root and link.get("name") in self.roots and len(self.roots) == 1):
            self.lint_inertial(link, owner)

        visuals = link.findall("visual")
        collisions = link.findall("collision")
        counters = {"visual": 0, "collision": 0}
        for shape in link:  # document order, numbered per kind
            if shape.tag in counters:
                counters[shape.tag] += 1
                self.lint_shape(shape, owner, f"{shape.tag} {counters[shape.tag]}: ")

        name = link.get("name") or ""
        if not collisions:
            if self.require_collision is None:
                if visuals:
                    self.add(
                        owner,
                        "has a <visual> but no <collision>; expected at least one "
                        "<collision> so the link takes part in contacts",
                    )
            elif self.require_collision(name):
                self.add(
                    owner,
                    "has no <collision>; expected at least one <collision> for this link",
                )

    def lint_inertial(self, link: ET.Element, owner: str) -> None:
        inertial = link.find("inertial")
        if inertial is None:
            self.add(
                owner,
                "has no <inertial>; expected an <inertial> with a positive <mass value> and an <inertia>",
            )
            return

        mass_elem = inertial.find("mass")
        if mass_elem is None or mass_elem.get("value") is None:
            self.add(owner, "<inertial> has no <mass value>; expected a positive mass in kg")
        else:
            mass = number(mass_elem, "value")
            if mass is not None and mass <= 0:
                self.add(owner, f"mass is {fmt(mass)} kg; expected a positive mass")

        inertia_elem = inertial.find("inertia")
        if inertia_elem is None:
            self.add(
                owner,
                "<inertial> has no <inertia>; expected <inertia ixx ixy ixz iyy iyz izz>",
            )
            return
        missing = [key for key in INERTIA_KEYS if inertia_elem.get(key) is None]
        if missing:
            self.add(
                owner,
                f"<inertia> lacks {', '.join(missing)}; expected all of {', '.join(INERTIA_KEYS)}",
            )
            return
        values = {key: number(inertia_elem, key) for key in INERTIA_KEYS}
        if any(v is None for v in values.values()):
            return  # reported as a non-finite number already
        tensor = np.array(
            [
                [values["ixx"], values["ixy"], values["ixz"]],
                [values["ixy"], values["iyy"], values["iyz"]],
                [values["ixz"], values["iyz"], values["izz"]],
            ],
            dtype=float,
        )
        moments = [float(m) for m in np.linalg.eigvalsh(tensor)]  # ascending
        if min(moments) <= 0:
            self.add(
                owner,
                f"inertia is not positive-definite: principal moments are "
                f"{vec(moments, derived=True)} kg*m^2; expected all principal moments > 0",
            )
            return
        small, middle, large = moments
        if large > (small + middle) + TRIANGLE_TOLERANCE * (small + middle + large):
            self.add(
                owner,
                f"principal moments {vec(moments, derived=True)} kg*m^2 break the triangle "
                f"inequality: {fmt_derived(large)} > {fmt_derived(small)} + "
                f"{fmt_derived(middle)}; expected each moment <= the sum of the other two",
            )

    def lint_shape(self, shape: ET.Element, owner: str, where: str) -> None:
        self.check_finite(shape, owner, where)
        geometry = shape.find("geometry")
        if geometry is None:
            self.add(
                owner,
                f"{where}has no <geometry>; expected one of {', '.join(ALLOWED_GEOMETRY)}",
            )
            return
        kinds = list(geometry)
        if len(kinds) != 1:
            found = ", ".join(f"<{k.tag}>" for k in kinds) or "nothing"
            self.add(
                owner,
                f"{where}<geometry> holds {found}; expected exactly one of {', '.join(ALLOWED_GEOMETRY)}",
            )
            return
        geom = kinds[0]
        if geom.tag == "capsule":
            self.add(owner, f"{where}capsule geometry is not standard URDF; {CAPSULE_HINT}")
            return
        if geom.tag not in ALLOWED_GEOMETRY:
            self.add(
                owner,
                f"{where}geometry <{geom.tag}> is not supported; expected one of {', '.join(ALLOWED_GEOMETRY)}",
            )
            return
        if geom.tag == "box":
            text = geom.get("size")
            if text is None:
                self.add(owner, f"{where}box has no size; expected three positive sizes in metres")
            else:
                size = parse_numbers(text, 3)
                if size is not None and min(size) <= 0:
                    self.add(
                        owner,
                        f"{where}box size is {vec(size)}; expected three positive sizes",
                    )
        elif geom.tag in ("cylinder", "sphere"):
            attrs = ("radius", "length") if geom.tag == "cylinder" else ("radius",)
            for attr in attrs:
                if geom.get(attr) is None:
                    self.add(
                        owner,
                        f"{where}{geom.tag} has no {attr}; expected a positive {attr} in metres",
                    )
                    continue
                value = number(geom, attr)
                if value is not None and value <= 0:
                    self.add(
                        owner,
                        f"{where}{geom.tag} {attr} is {fmt(value)}; expected a positive {attr}",
                    )
        else:  # mesh
            self.lint_mesh(geom, owner, where)

    def lint_mesh(self, mesh: ET.Element, owner: str, where: str) -> None:
        scale_text = mesh.get("scale")
        if scale_text is not None:
            scale = parse_numbers(scale_text, 3)
            if scale is not None and any(s == 0 for s in scale):
                self.add(
                    owner,
                    f"{where}mesh scale is {vec(scale)}; expected three non-zero factors",
                )
        filename = mesh.get("filename")
        if not filename:
            self.add(owner, f"{where}mesh has no filename; expected the path of a mesh file")
            return
        if filename.startswith("package://"):
            self.add(
                owner,
                f"{where}mesh filename {filename!r} uses package://, which needs ROS to "
                f"resolve; expected an absolute path (or one relative to the URDF's folder)",
            )
            return
        path_text = filename[len("file://") :] if filename.startswith("file://") else filename
        path = Path(path_text)
        if not path.is_absolute():
            path = (self.base_dir if self.base_dir is not None else Path.cwd()) / path
        if not path.is_file():
            self.add(
                owner,
                f"{where}mesh file {filename!r} does not exist (looked for {path}); expected an existing mesh file",
            )

    # -- joints -------------------------------------------------------------------------

    def lint_joint(self, joint: ET.Element, owner: str) -> None:
        self.check_finite(joint, owner)
        joint_type = joint.get("type")
        if joint_type is None:
            self.add(
                owner,
                f"has no type; expected one of {', '.join(ALLOWED_JOINT_TYPES)}",
            )
            return
        if joint_type not in KNOWN_JOINT_TYPES:
            self.add(
                owner,
                f"type {joint_type!r} is not a URDF joint type; expected one of {', '.join(ALLOWED_JOINT_TYPES)}",
            )
            return
        if joint_type not in ALLOWED_JOINT_TYPES:
            self.add(
                owner,
                f"type {joint_type!r} is not allowed in generated scenes; expected one of "
                f"{', '.join(ALLOWED_JOINT_TYPES)}",
            )
            return
        if joint_type == "fixed":
            return
        self.lint_limit(joint, owner, joint_type)
        self.lint_axis(joint, owner)

    def lint_limit(self, joint: ET.Element, owner: str, joint_type: str) -> None:
        limit = joint.find("limit")
        if limit is None:
            if joint_type in MOVABLE_LIMITED:
                expected = "<limit lower upper effort velocity> with lower < upper, effort > 0 and velocity > 0"
            else:
                expected = "<limit effort velocity> with effort > 0 and velocity > 0"
            self.add(owner, f"{joint_type} joint has no <limit>; expected {expected}")
            return
        if joint_type in MOVABLE_LIMITED:
            bounds = {}
            for attr in ("lower", "upper"):
                if limit.get(attr) is None:
                    self.add(
                        owner,
                        f"<limit> has no {attr}; expected finite lower < upper for a {joint_type} joint",
                    )
                else:
                    bounds[attr] = number(limit, attr)
            lower, upper = bounds.get("lower"), bounds.get("upper")
            if lower is not None and upper is not None and not lower < upper:
                self.add(
                    owner,
                    f"lower limit {fmt(lower)} is not below upper limit {fmt(upper)}; expected lower < upper",
                )
        for attr in ("effort", "velocity"):
            if limit.get(attr) is None:
                self.add(owner, f"<limit> has no {attr}; expected {attr} > 0")
                continue
            value = number(limit, attr)
            if value is not None and value <= 0:
                self.add(owner, f"<limit> {attr} is {fmt(value)}; expected {attr} > 0")

    def lint_axis(self, joint: ET.Element, owner: str) -> None:
        axis_elem = joint.find("axis")
        if axis_elem is None:
            return  # URDF's default axis (1, 0, 0) is a unit vector
        text = axis_elem.get("xyz")
        if text is None:
            self.add(owner, "<axis> has no xyz; expected a unit vector such as '0 0 1'")
            return
        axis = parse_numbers(text, 3)
        if axis is None:
            return  # reported as a non-finite number already
        length = math.sqrt(sum(a * a for a in axis))
        if length == 0:
            self.add(owner, f"axis is {vec(axis)}; expected a non-zero unit vector")
        elif abs(length - 1.0) >= AXIS_TOLERANCE:
            self.add(
                owner,
                f"axis {vec(axis)} has length {fmt_derived(length)}; expected a unit vector (length 1 within 1e-6)",
            )

"""The compiler's own check of every URDF it writes (design decision 2, "Standard URDF").

`lint_urdf` reads a rendered URDF document and returns a list of `LintProblem`s, one per
fault, each naming the template, the link or joint, what is wrong (with the offending numbers)
and what was expected. An empty list means the document is standard URDF that PyBullet,
yourdfpy and urdfdom's ``check_urdf`` all accept and that simulates sensibly:

a. every link has an ``<inertial>`` with a positive ``<mass value>``; every number in the
   document is finite;
b. every inertia tensor is positive-definite and its principal moments satisfy the triangle
   inequality;
c. revolute and prismatic joints have ``<limit>`` with finite lower < upper, effort > 0 and
   velocity > 0; continuous joints have effort > 0 and velocity > 0; no floating or planar
   joints;
d. the axis of every movable joint is a non-zero unit vector;
e. geometry is only box, cylinder, sphere or mesh, with positive sizes;
f. links that need collision geometry have at least one ``<collision>``;
g. mesh files exist (no ``package://``);
h. the links and joints form one tree: unique names, exactly one root link, every joint's
   parent and child exist, no link has two parent joints.

Only the standard library and numpy are used; the module imports nothing heavy.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = [
    "LintError",
    "LintProblem",
    "check_urdf_or_raise",
    "lint_urdf",
    "pybullet_crash_risks",
]

#: Joint types a generated scene may use.
MOVABLE_LIMITED = ("revolute", "prismatic")
ALLOWED_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed")
KNOWN_JOINT_TYPES = ALLOWED_JOINT_TYPES + ("floating", "planar")
ALLOWED_GEOMETRY = ("box", "cylinder", "sphere", "mesh")
CAPSULE_HINT = (
    "write a capsule as a cylinder plus two spheres "
    "(capsule_shapes in templates/common/shapes.xacro)"
)
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


@dataclass(frozen=True)
class LintProblem:
    """One fault in a rendered URDF.

    ``template`` names the template (or file) the document came from, ``element`` the thing at
    fault (``"link 'forearm'"``, ``"joint 'elbow'"``, ``"robot 'jaco'"``, ``"document"``) and
    ``message`` says what is wrong and what was expected.
    """

    template: str
    element: str
    message: str

    def __str__(self) -> str:
        return f"{self.template}: {self.element}: {self.message}"


class LintError(Exception):
    """Raised by `check_urdf_or_raise` when a document has problems; one problem per line."""

    def __init__(self, problems: list[LintProblem]) -> None:
        self.problems: list[LintProblem] = list(problems)
        super().__init__("\n".join(str(problem) for problem in self.problems))


# --------------------------------------------------------------------------- number helpers


def _fmt(value: float) -> str:
    """A number the user wrote, shown exactly (``-1.0``, ``0.3``, ``1e-05``)."""
    return repr(float(value))


def _fmt_derived(value: float) -> str:
    """A number the linter computed (eigenvalues, lengths), shown to 6 significant digits."""
    text = f"{float(value):.6g}"
    return "0" if text == "-0" else text


def _vec(values: tuple[float, ...] | list[float], derived: bool = False) -> str:
    fmt = _fmt_derived if derived else _fmt
    return "(" + ", ".join(fmt(v) for v in values) + ")"


def _parse_numbers(text: str | None, count: int) -> tuple[float, ...] | None:
    """``count`` finite floats from a whitespace-separated attribute, else None."""
    if text is None:
        return None
    parts = text.split()
    if len(parts) != count:
        return None
    try:
        values = tuple(float(part) for part in parts)
    except ValueError:
        return None
    if not all(math.isfinite(v) for v in values):
        return None
    return values


def _number(elem: ET.Element, attr: str) -> float | None:
    values = _parse_numbers(elem.get(attr), 1)
    return None if values is None else values[0]


def _plural(count: int, word: str) -> str:
    return f"{count} {word}" if count == 1 else f"{count} {word}s"


# --------------------------------------------------------------------------- the linter


class _Linter:
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
        self.roots = {l.get("name") for l in links} - children
        for index, link in enumerate(links, start=1):
            self.lint_link(link, self.label("link", link, index))
        for index, joint in enumerate(joints, start=1):
            self.lint_joint(joint, self.label("joint", joint, index))
        for index, material in enumerate(root.findall("material"), start=1):
            self.check_finite(material, self.label("material", material, index))
        self.lint_structure(root, links, joints)
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
            if text is not None and _parse_numbers(text, count) is None:
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
                "has no <inertial>; expected an <inertial> with a positive <mass value> "
                "and an <inertia>",
            )
            return

        mass_elem = inertial.find("mass")
        if mass_elem is None or mass_elem.get("value") is None:
            self.add(owner, "<inertial> has no <mass value>; expected a positive mass in kg")
        else:
            mass = _number(mass_elem, "value")
            if mass is not None and mass <= 0:
                self.add(owner, f"mass is {_fmt(mass)} kg; expected a positive mass")

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
                f"<inertia> lacks {', '.join(missing)}; expected all of "
                f"{', '.join(INERTIA_KEYS)}",
            )
            return
        values = {key: _number(inertia_elem, key) for key in INERTIA_KEYS}
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
                f"{_vec(moments, derived=True)} kg*m^2; expected all principal moments > 0",
            )
            return
        small, middle, large = moments
        if large > (small + middle) + TRIANGLE_TOLERANCE * (small + middle + large):
            self.add(
                owner,
                f"principal moments {_vec(moments, derived=True)} kg*m^2 break the triangle "
                f"inequality: {_fmt_derived(large)} > {_fmt_derived(small)} + "
                f"{_fmt_derived(middle)}; expected each moment <= the sum of the other two",
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
                f"{where}<geometry> holds {found}; expected exactly one of "
                f"{', '.join(ALLOWED_GEOMETRY)}",
            )
            return
        geom = kinds[0]
        if geom.tag == "capsule":
            self.add(owner, f"{where}capsule geometry is not standard URDF; {CAPSULE_HINT}")
            return
        if geom.tag not in ALLOWED_GEOMETRY:
            self.add(
                owner,
                f"{where}geometry <{geom.tag}> is not supported; expected one of "
                f"{', '.join(ALLOWED_GEOMETRY)}",
            )
            return
        if geom.tag == "box":
            text = geom.get("size")
            if text is None:
                self.add(owner, f"{where}box has no size; expected three positive sizes in metres")
            else:
                size = _parse_numbers(text, 3)
                if size is not None and min(size) <= 0:
                    self.add(
                        owner,
                        f"{where}box size is {_vec(size)}; expected three positive sizes",
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
                value = _number(geom, attr)
                if value is not None and value <= 0:
                    self.add(
                        owner,
                        f"{where}{geom.tag} {attr} is {_fmt(value)}; expected a positive {attr}",
                    )
        else:  # mesh
            self.lint_mesh(geom, owner, where)

    def lint_mesh(self, mesh: ET.Element, owner: str, where: str) -> None:
        scale_text = mesh.get("scale")
        if scale_text is not None:
            scale = _parse_numbers(scale_text, 3)
            if scale is not None and any(s == 0 for s in scale):
                self.add(
                    owner,
                    f"{where}mesh scale is {_vec(scale)}; expected three non-zero factors",
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
        path_text = filename[len("file://"):] if filename.startswith("file://") else filename
        path = Path(path_text)
        if not path.is_absolute():
            path = (self.base_dir if self.base_dir is not None else Path.cwd()) / path
        if not path.is_file():
            self.add(
                owner,
                f"{where}mesh file {filename!r} does not exist (looked for {path}); "
                f"expected an existing mesh file",
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
                f"type {joint_type!r} is not a URDF joint type; expected one of "
                f"{', '.join(ALLOWED_JOINT_TYPES)}",
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
                expected = (
                    "<limit lower upper effort velocity> with lower < upper, "
                    "effort > 0 and velocity > 0"
                )
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
                        f"<limit> has no {attr}; expected finite lower < upper for a "
                        f"{joint_type} joint",
                    )
                else:
                    bounds[attr] = _number(limit, attr)
            lower, upper = bounds.get("lower"), bounds.get("upper")
            if lower is not None and upper is not None and not lower < upper:
                self.add(
                    owner,
                    f"lower limit {_fmt(lower)} is not below upper limit {_fmt(upper)}; "
                    f"expected lower < upper",
                )
        for attr in ("effort", "velocity"):
            if limit.get(attr) is None:
                self.add(owner, f"<limit> has no {attr}; expected {attr} > 0")
                continue
            value = _number(limit, attr)
            if value is not None and value <= 0:
                self.add(owner, f"<limit> {attr} is {_fmt(value)}; expected {attr} > 0")

    def lint_axis(self, joint: ET.Element, owner: str) -> None:
        axis_elem = joint.find("axis")
        if axis_elem is None:
            return  # URDF's default axis (1, 0, 0) is a unit vector
        text = axis_elem.get("xyz")
        if text is None:
            self.add(owner, "<axis> has no xyz; expected a unit vector such as '0 0 1'")
            return
        axis = _parse_numbers(text, 3)
        if axis is None:
            return  # reported as a non-finite number already
        length = math.sqrt(sum(a * a for a in axis))
        if length == 0:
            self.add(owner, f"axis is {_vec(axis)}; expected a non-zero unit vector")
        elif abs(length - 1.0) >= AXIS_TOLERANCE:
            self.add(
                owner,
                f"axis {_vec(axis)} has length {_fmt_derived(length)}; expected a unit vector "
                "(length 1 within 1e-6)",
            )

    # -- rule h: structure --------------------------------------------------------------

    def lint_structure(
        self, root: ET.Element, links: list[ET.Element], joints: list[ET.Element]
    ) -> None:
        robot = f"robot '{root.get('name')}'" if root.get("name") else "robot (unnamed)"
        if not links:
            self.add(robot, "has no <link>; expected at least one link")
            return

        link_names: list[str] = []
        for index, link in enumerate(links, start=1):
            name = link.get("name")
            if not name:
                self.add(self.label("link", link, index), "has no name; expected a unique name")
            else:
                link_names.append(name)
        self.report_duplicates("link", link_names)
        joint_names = [j.get("name") for j in joints if j.get("name")]
        for index, joint in enumerate(joints, start=1):
            if not joint.get("name"):
                self.add(self.label("joint", joint, index), "has no name; expected a unique name")
        self.report_duplicates("joint", joint_names)

        known = set(link_names)
        parents_of: dict[str, list[str]] = {}
        children_of: dict[str, list[str]] = {}
        for index, joint in enumerate(joints, start=1):
            owner = self.label("joint", joint, index)
            ends = {}
            for role in ("parent", "child"):
                elem = joint.find(role)
                name = elem.get("link") if elem is not None else None
                if not name:
                    self.add(
                        owner,
                        f"has no <{role} link>; expected the name of a link in this document",
                    )
                elif name not in known:
                    self.add(
                        owner,
                        f"{role} link {name!r} does not exist; expected the name of a link "
                        f"in this document",
                    )
                else:
                    ends[role] = name
            if "child" in ends:
                parents_of.setdefault(ends["child"], []).append(joint.get("name") or owner)
            if "parent" in ends and "child" in ends:
                children_of.setdefault(ends["parent"], []).append(ends["child"])

        for name in dict.fromkeys(link_names):
            joints_in = parents_of.get(name, [])
            if len(joints_in) > 1:
                listed = ", ".join(repr(j) for j in joints_in)
                self.add(
                    f"link '{name}'",
                    f"is the child of {len(joints_in)} joints ({listed}); expected at most one "
                    f"parent joint",
                    crash_prone=True,
                )

        roots = [name for name in dict.fromkeys(link_names) if name not in parents_of]
        if not roots:
            self.add(
                robot,
                "has no root link (every link is the child of a joint, so the joints form a "
                "cycle); expected exactly one root link",
            )
            return
        if len(roots) > 1:
            listed = ", ".join(repr(r) for r in roots)
            self.add(
                robot,
                f"has {len(roots)} root links ({listed}); expected exactly one root link "
                f"(connect the others with joints)",
                crash_prone=True,
            )
            return
        # One root: every link must hang from it (anything else sits on a cycle).
        reached = {roots[0]}
        frontier = [roots[0]]
        while frontier:
            for child in children_of.get(frontier.pop(), []):
                if child not in reached:
                    reached.add(child)
                    frontier.append(child)
        for name in dict.fromkeys(link_names):
            if name not in reached:
                self.add(
                    f"link '{name}'",
                    f"is not reachable from the root link {roots[0]!r} (its joints form a "
                    f"cycle); expected the links and joints to form a tree",
                    crash_prone=True,
                )

    def report_duplicates(self, kind: str, names: list[str]) -> None:
        counts: dict[str, int] = {}
        for name in names:
            counts[name] = counts.get(name, 0) + 1
        for name, count in counts.items():
            if count > 1:
                self.add(
                    f"{kind} '{name}'",
                    f"name is used by {_plural(count, kind)}; expected unique {kind} names",
                )


def lint_urdf(
    urdf_xml: str,
    *,
    template: str,
    base_dir: Path | None = None,
    require_collision: Callable[[str], bool] | None = None,
    static_root: bool = False,
) -> list[LintProblem]:
    """Check a rendered URDF document; return its problems in document order (empty = clean).

    ``template`` names where the document came from (it prefixes every problem).
    ``base_dir`` is the folder relative mesh filenames resolve against (the folder the URDF is
    written to; the current directory when None). ``require_collision(link_name)`` says which
    links must have a ``<collision>``; by default every link with a ``<visual>`` must.
    A malformed document is reported as one problem. ``static_root``: the document will be loaded
    with a fixed base, so its root link may be massless (a common convention in robot URDFs such as
    pybullet_data's KUKA iiwa; a fixed base never moves, so its mass plays no part). Our own
    templates are linted without it.
    """
    return _Linter(template, base_dir, require_collision, static_root).run(urdf_xml)


def pybullet_crash_risks(urdf_xml: str, *, template: str = "") -> list[LintProblem]:
    """The structure problems (several root links, a link with two parent joints, links on a
    cycle) on which PyBullet 3.2.7's ``loadURDF`` crashes the process instead of failing."""
    linter = _Linter(template, None, None)
    try:
        root = ET.fromstring(urdf_xml)
    except (ET.ParseError, ValueError):
        return []
    if root.tag != "robot":
        return []
    linter.lint_structure(root, root.findall("link"), root.findall("joint"))
    if len(linter.problems) > len(linter.crash_prone):
        # Unknown or duplicate link names: PyBullet rejects the file cleanly before it gets
        # to building the tree.
        return []
    return linter.crash_prone


def check_urdf_or_raise(
    urdf_xml: str,
    *,
    template: str,
    base_dir: Path | None = None,
    require_collision: Callable[[str], bool] | None = None,
) -> None:
    """`lint_urdf`, raising `LintError` (one problem per line) when anything is found."""
    problems = lint_urdf(
        urdf_xml, template=template, base_dir=base_dir, require_collision=require_collision
    )
    if problems:
        raise LintError(problems)

"""Compile-time merging of the links that hang on ``fixed`` joints.

PyBullet pays solver and collision time for every link of a multibody, including links on fixed
joints (the person template bakes a task's static posture into fixed joints, so most of its 42
links are rigidly attached). PyBullet's own ``URDF_MERGE_FIXED_LINKS`` load flag removes those
links but also their frames, which the compiler still needs (landmarks such as
``right_wrist``). `merge_fixed_links` therefore rewrites the URDF itself and returns, for every
link it removed, where that link's frame now sits on the link it was merged into.

Merging link C into its parent P through fixed joint J (origin ``T_J``):

- C's ``<visual>`` and ``<collision>`` elements move into P with origins ``T_J * T_elem``;
- C's ``<inertial>`` is combined with P's: total mass, mass-weighted centre of mass, and the
  inertia tensor about the combined centre of mass (each part rotated into P's frame and shifted
  with the parallel-axis theorem), written as a full symmetric tensor in an inertial frame with
  ``rpy="0 0 0"`` (pybullet reports joint axes in the child's inertial frame, so inertial frames
  stay aligned with their link). A link without ``<inertial>`` contributes nothing (URDF's
  meaning of a missing inertial), and a link whose inertial is untouched keeps its element;
- the joints whose parent is C are re-parented to P with origins ``T_J * T_child`` (axes are in
  the joint frame, so they do not change);
- J and C are removed. Other children of C (``<contact>`` and the like) are dropped.

Chains of fixed joints collapse completely (C's own merged children travel with it). Links named
in ``keep`` and the root link always stay.

Only numbers this module computes are rewritten: they are rounded to 12 significant digits,
components below 1e-12 of the largest one of the same vector or tensor (or of the numbers they
were computed from: the 6e-17 that 1 - 1 leaves) are written as 0, and every float is written
with ``repr``. Elements that are not touched keep their text. The output
is deterministic: same input, same bytes.

Its frame arithmetic (:class:`Pose`, :func:`origin_pose`, :func:`write_origin`) also serves
:mod:`.weld`.

Pure Python + numpy + ``xml.etree``; no pybullet.
"""

from __future__ import annotations

import copy
import math
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from ..rotation import matrix_quat, matrix_rpy, rpy_matrix

__all__ = ["MergedFrame", "Pose", "merge_fixed_links", "origin_pose", "parse_vector", "reindent", "write_origin"]

_SIGNIFICANT_DIGITS = 12
_RELATIVE_ZERO = 1e-12
_GEOMETRY_TAGS = ("visual", "collision")
_INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


@dataclass(frozen=True)
class MergedFrame:
    """Where the frame of a merged link went."""

    #: The surviving link the frame now rides on.
    into: str
    #: Frame origin in ``into``'s frame (m).
    xyz: tuple[float, float, float]
    #: Frame orientation in ``into``'s frame, quaternion (x, y, z, w) with w >= 0.
    quat: tuple[float, float, float, float]


class Pose:
    """A rigid transform (rotation ``rot``, translation ``pos``). ``scale`` bounds the size of
    the translations it was computed from, so that rounding noise left by cancellation (1 - 1 =
    6e-17) can be told from a real offset."""

    __slots__ = ("rot", "pos", "scale")

    def __init__(self, rot: np.ndarray, pos: np.ndarray, scale: float | None = None) -> None:
        self.rot = rot
        self.pos = pos
        self.scale = float(np.abs(pos).max()) if scale is None else scale

    @staticmethod
    def identity() -> Pose:
        return Pose(np.eye(3), np.zeros(3))

    def __mul__(self, other: Pose) -> Pose:
        return Pose(self.rot @ other.rot, self.rot @ other.pos + self.pos, self.scale + other.scale)


# --------------------------------------------------------------------------- number I/O


def parse_vector(text: str | None, what: str) -> np.ndarray:
    if text is None:
        return np.zeros(3)
    parts = text.split()
    try:
        values = [float(v) for v in parts]
    except ValueError:
        values = []
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"{what} is {text!r}; expected three finite numbers")
    return np.array(values)


def _parse_scalar(elem: ET.Element, attr: str, what: str) -> float:
    text = elem.get(attr)
    try:
        value = float(text) if text is not None else 0.0
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ValueError(f"{what} {attr} is {text!r}; expected a finite number")
    return value


def origin_pose(parent: ET.Element, what: str) -> Pose:
    origin = parent.find("origin")
    if origin is None:
        return Pose.identity()
    xyz = parse_vector(origin.get("xyz"), f"{what} <origin xyz>")
    rpy = parse_vector(origin.get("rpy"), f"{what} <origin rpy>")
    return Pose(rpy_matrix(rpy), xyz)


def _round(value: float) -> float:
    rounded = float(f"{float(value):.{_SIGNIFICANT_DIGITS}g}")
    return rounded + 0.0  # -0.0 -> 0.0


def _clean(values: Sequence[float], scale: float = 0.0) -> list[float]:
    """Round to 12 significant digits; components below 1e-12 of the largest one, or of
    ``scale`` (the size of the numbers they were computed from), become 0."""
    scale = max([scale] + [abs(float(v)) for v in values])
    return [0.0 if abs(float(v)) <= _RELATIVE_ZERO * scale else _round(v) for v in values]


def _fmt(values: Sequence[float]) -> str:
    return " ".join(repr(v) for v in values)


def write_origin(parent: ET.Element, pose: Pose, *, index: int = 0) -> None:
    """Replace (or insert at ``index``) ``parent``'s ``<origin>`` with ``pose``."""
    origin = parent.find("origin")
    if origin is None:
        origin = ET.Element("origin")
        parent.insert(index, origin)
    origin.attrib.clear()
    origin.set("xyz", _fmt(_clean(pose.pos, pose.scale)))
    angles = [_round(a) for a in matrix_rpy(pose.rot)]
    origin.set("rpy", _fmt([0.0 if abs(a) <= _RELATIVE_ZERO else a for a in angles]))


# --------------------------------------------------------------------------- inertia


def _read_inertial(link: ET.Element, name: str) -> tuple[float, np.ndarray, np.ndarray] | None:
    """(mass, centre of mass, inertia tensor about the COM), both in the link frame."""
    inertial = link.find("inertial")
    if inertial is None:
        return None
    what = f"link {name!r} <inertial>"
    pose = origin_pose(inertial, what)
    mass_elem = inertial.find("mass")
    mass = 0.0 if mass_elem is None else _parse_scalar(mass_elem, "value", f"{what} <mass>")
    inertia_elem = inertial.find("inertia")
    tensor = np.zeros((3, 3))
    if inertia_elem is not None:
        v = {k: _parse_scalar(inertia_elem, k, f"{what} <inertia>") for k in _INERTIA_KEYS}
        tensor = np.array(
            [
                [v["ixx"], v["ixy"], v["ixz"]],
                [v["ixy"], v["iyy"], v["iyz"]],
                [v["ixz"], v["iyz"], v["izz"]],
            ]
        )
    return mass, pose.pos, pose.rot @ tensor @ pose.rot.T


def _combined_inertial(parts: list[tuple[float, np.ndarray, np.ndarray]]) -> ET.Element:
    """One ``<inertial>`` (unrotated frame at the combined COM) for parts given in one frame."""
    total = sum(m for m, _, _ in parts)
    if total > 0.0:
        com = sum(m * c for m, c, _ in parts) / total
    else:
        com = np.zeros(3)
    com_scale = max(float(np.abs(c).max()) for _, c, _ in parts)
    tensor = np.zeros((3, 3))
    tensor_scale = 0.0
    for mass, centre, inertia in parts:
        d = centre - com
        term = inertia + mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
        tensor += term
        tensor_scale = max(tensor_scale, float(np.abs(term).max()))
    tensor = 0.5 * (tensor + tensor.T)

    inertial = ET.Element("inertial")
    ET.SubElement(inertial, "origin", {"xyz": _fmt(_clean(com, com_scale)), "rpy": "0.0 0.0 0.0"})
    ET.SubElement(inertial, "mass", {"value": repr(_round(total))})
    values = [tensor[0, 0], tensor[0, 1], tensor[0, 2], tensor[1, 1], tensor[1, 2], tensor[2, 2]]
    ET.SubElement(inertial, "inertia", dict(zip(_INERTIA_KEYS, map(repr, _clean(values, tensor_scale)))))
    return inertial


# --------------------------------------------------------------------------- formatting


def reindent(elem: ET.Element, level: int = 0) -> None:
    """Two-space indentation, whitespace-only text dropped (moved elements carry odd tails)."""
    pad = "\n" + "  " * (level + 1)
    children = list(elem)
    if elem.text is not None and not elem.text.strip():
        elem.text = None
    if children:
        if elem.text is None:
            elem.text = pad
        for child in children:
            reindent(child, level + 1)
            if child.tail is None or not child.tail.strip():
                child.tail = pad
        children[-1].tail = "\n" + "  " * level
    if elem.tail is not None and not elem.tail.strip():
        elem.tail = None


# --------------------------------------------------------------------------- the merge


@dataclass
class _Tree:
    """A URDF document's tree: links by name, joints in document order, each link's parent joint
    and child joints, the root link, and the links the merge must keep."""

    root: ET.Element
    links: dict[str, ET.Element]
    joints: list[ET.Element]
    parent_joint: dict[str, ET.Element]  # child link -> its joint
    child_joints: dict[str, list[ET.Element]]
    root_link: str
    keep: set[str]

    def merged(self, name: str) -> bool:
        """Whether link ``name`` is merged into its parent: its joint is fixed and it is not kept."""
        joint = self.parent_joint.get(name)
        return joint is not None and joint.get("type") == "fixed" and name not in self.keep


def merge_fixed_links(urdf_xml: str, *, keep: Iterable[str] = ()) -> tuple[str, dict[str, MergedFrame]]:
    """Merge every link whose parent joint is ``fixed`` into its parent (transitively).

    Returns the merged URDF document and, for every merged link, its `MergedFrame` on the link
    that survives (in document order of the original links). Links in ``keep`` and the root
    link are never merged; a kept link keeps its fixed joint (re-parented onto the surviving
    link if its own parent was merged). See the module docstring for what moves where.

    Raises ValueError when the document is not a URDF tree (malformed XML, no ``<robot>`` root,
    duplicate names, a joint naming a missing link, a link with two parent joints, not exactly
    one root link), when a number it needs is not finite, or when ``keep`` names a link the
    document lacks.
    """
    tree = _parse_tree(urdf_xml, set(keep))
    survivor, in_survivor = _survivors(tree)
    for name, absorbed in _merged_order(tree).items():
        _absorb(tree, name, absorbed, in_survivor)
    _drop_merged(tree, survivor, in_survivor)
    frames = {}
    for name in tree.links:
        if tree.merged(name):
            pose = in_survivor[name]
            xyz = tuple(float(v) + 0.0 for v in pose.pos)
            frames[name] = MergedFrame(survivor[name], xyz, matrix_quat(pose.rot))  # type: ignore[arg-type]
    reindent(tree.root)
    text = '<?xml version="1.0"?>\n' + ET.tostring(tree.root, encoding="unicode") + "\n"
    return text, frames


def _parse_tree(urdf_xml: str, keep_set: set[str]) -> _Tree:
    """The document's tree; ValueError when it is not one (see :func:`merge_fixed_links`)."""
    try:
        root = ET.fromstring(urdf_xml)
    except ET.ParseError as exc:
        raise ValueError(f"not well-formed XML: {exc}") from None
    if root.tag != "robot":
        raise ValueError(f"root element is <{root.tag}>; expected <robot>")

    links: dict[str, ET.Element] = {}
    for link in root.findall("link"):
        name = link.get("name")
        if not name:
            raise ValueError("a <link> has no name")
        if name in links:
            raise ValueError(f"link name {name!r} is used twice")
        links[name] = link
    unknown = sorted(keep_set - set(links))
    if unknown:
        raise ValueError(f"keep names links the document lacks: {', '.join(unknown)}")

    joints = root.findall("joint")
    parent_joint: dict[str, ET.Element] = {}  # child link -> its joint
    child_joints: dict[str, list[ET.Element]] = {name: [] for name in links}
    joint_names: set[str] = set()
    for joint in joints:
        jname = joint.get("name") or "(unnamed)"
        if jname in joint_names:
            raise ValueError(f"joint name {jname!r} is used twice")
        joint_names.add(jname)
        ends = {}
        for role in ("parent", "child"):
            elem = joint.find(role)
            lname = elem.get("link") if elem is not None else None
            if lname not in links:
                raise ValueError(f"joint {jname!r}: {role} link {lname!r} does not exist")
            ends[role] = lname
        child = ends["child"]
        if child in parent_joint:
            raise ValueError(f"link {child!r} is the child of two joints")
        parent_joint[child] = joint
        child_joints[ends["parent"]].append(joint)
    roots = [name for name in links if name not in parent_joint]
    if len(roots) != 1:
        raise ValueError(f"expected exactly one root link, found {len(roots)}: {roots}")
    return _Tree(root, links, joints, parent_joint, child_joints, roots[0], keep_set)


def _survivors(tree: _Tree) -> tuple[dict[str, str], dict[str, Pose]]:
    """Walk the tree from the root (joint document order): each link's surviving link and its
    pose there (identity for a survivor). ValueError for links not reachable from the root."""
    root_link = tree.root_link
    survivor: dict[str, str] = {root_link: root_link}
    in_survivor: dict[str, Pose] = {root_link: Pose.identity()}
    visited = {root_link}
    stack = [root_link]
    while stack:
        name = stack.pop()
        for joint in reversed(tree.child_joints[name]):
            child = joint.find("child").get("link")  # type: ignore[union-attr]
            visited.add(child)
            if tree.merged(child):
                jname = joint.get("name")
                survivor[child] = survivor[name]
                in_survivor[child] = in_survivor[name] * origin_pose(joint, f"joint {jname!r}")
            else:
                survivor[child] = child
                in_survivor[child] = Pose.identity()
            stack.append(child)
    if len(visited) != len(tree.links):
        missing = [n for n in tree.links if n not in visited]
        raise ValueError(f"links on a cycle, not reachable from root {root_link!r}: {missing}")
    return survivor, in_survivor


def _merged_order(tree: _Tree) -> dict[str, list[str]]:
    """Surviving link -> the links merged into it, depth-first (pre-order), children in joint order."""

    def collect(name: str, into: list[str]) -> None:
        for joint in tree.child_joints[name]:
            child = joint.find("child").get("link")  # type: ignore[union-attr]
            if tree.merged(child):
                into.append(child)
                collect(child, into)

    merged_order: dict[str, list[str]] = {}
    for name in tree.links:
        if not tree.merged(name):
            order: list[str] = []
            collect(name, order)
            if order:
                merged_order[name] = order
    return merged_order


def _absorb(tree: _Tree, name: str, absorbed: list[str], in_survivor: dict[str, Pose]) -> None:
    """Rewrite surviving link ``name``: one inertial for it and the ``absorbed`` links, and their
    visuals and collisions moved into its frame."""
    link = tree.links[name]
    parts = []
    own = _read_inertial(link, name)
    if own is not None:
        parts.append(own)
    moved: list[ET.Element] = []
    for child in absorbed:
        pose = in_survivor[child]
        child_link = tree.links[child]
        part = _read_inertial(child_link, child)
        if part is not None:
            mass, com, tensor = part
            parts.append((mass, pose.rot @ com + pose.pos, pose.rot @ tensor @ pose.rot.T))
        for elem in child_link:
            if elem.tag in _GEOMETRY_TAGS:
                new = copy.deepcopy(elem)
                elem_pose = origin_pose(elem, f"link {child!r} <{elem.tag}>")
                write_origin(new, pose * elem_pose)
                moved.append(new)
    if len(parts) > (1 if own is not None else 0):
        combined = _combined_inertial(parts)
        old = link.find("inertial")
        if old is not None:
            index = list(link).index(old)
            link.remove(old)
            link.insert(index, combined)
        else:
            link.insert(0, combined)
    link.extend(moved)


def _drop_merged(tree: _Tree, survivor: dict[str, str], in_survivor: dict[str, Pose]) -> None:
    """Re-parent the joints of merged links onto their survivors; drop merged links and their joints."""
    for joint in tree.joints:
        child = joint.find("child").get("link")  # type: ignore[union-attr]
        if tree.merged(child):
            tree.root.remove(joint)
            continue
        parent_elem = joint.find("parent")
        parent = parent_elem.get("link")  # type: ignore[union-attr]
        if tree.merged(parent):
            parent_elem.set("link", survivor[parent])  # type: ignore[union-attr]
            jpose = origin_pose(joint, f"joint {joint.get('name')!r}")
            write_origin(joint, in_survivor[parent] * jpose, index=0)
    for name, link in tree.links.items():
        if tree.merged(name):
            tree.root.remove(link)

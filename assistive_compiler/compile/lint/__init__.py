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

Rules a–g are checked per element in :mod:`.linter`, rule h in :mod:`.tree`; :mod:`.problems`
holds what is reported, :mod:`.numbers` how numbers are read and shown. Only the standard
library and numpy are used; the package imports nothing heavy.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path

from .linter import Linter
from .problems import LintError, LintProblem
from .tree import lint_tree

__all__ = [
    "LintError",
    "LintProblem",
    "check_urdf_or_raise",
    "lint_urdf",
    "pybullet_crash_risks",
]


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
    return Linter(template, base_dir, require_collision, static_root).run(urdf_xml)


def pybullet_crash_risks(urdf_xml: str, *, template: str = "") -> list[LintProblem]:
    """The structure problems (several root links, a link with two parent joints, links on a
    cycle) on which PyBullet 3.2.7's ``loadURDF`` crashes the process instead of failing."""
    linter = Linter(template, None, None)
    try:
        root = ET.fromstring(urdf_xml)
    except (ET.ParseError, ValueError):
        return []
    if root.tag != "robot":
        return []
    lint_tree(linter, root, root.findall("link"), root.findall("joint"))
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
    problems = lint_urdf(urdf_xml, template=template, base_dir=base_dir, require_collision=require_collision)
    if problems:
        raise LintError(problems)

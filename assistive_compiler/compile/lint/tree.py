"""Lint rule h: the links and joints form one tree — unique names, exactly one root link, every
joint's parent and child exist, no link has two parent joints, no cycles.

:func:`lint_tree` takes the linter (its ``add`` records a problem) and the document's root,
links and joints; it reports through ``add``, marking the faults that crash PyBullet 3.2.7's
``loadURDF`` (several roots, two parent joints, a cycle) ``crash_prone``."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from .numbers import plural


def lint_tree(linter, root: ET.Element, links: list[ET.Element], joints: list[ET.Element]) -> None:
    robot = f"robot '{root.get('name')}'" if root.get("name") else "robot (unnamed)"
    if not links:
        linter.add(robot, "has no <link>; expected at least one link")
        return
    link_names = _unique_names(linter, links, joints)
    parents_of, children_of = _joint_ends(linter, joints, set(link_names))
    for name in dict.fromkeys(link_names):
        joints_in = parents_of.get(name, [])
        if len(joints_in) > 1:
            listed = ", ".join(repr(j) for j in joints_in)
            linter.add(
                f"link '{name}'",
                f"is the child of {len(joints_in)} joints ({listed}); expected at most one parent joint",
                crash_prone=True,
            )
    roots = [name for name in dict.fromkeys(link_names) if name not in parents_of]
    if not roots:
        linter.add(
            robot,
            "has no root link (every link is the child of a joint, so the joints form a "
            "cycle); expected exactly one root link",
        )
        return
    if len(roots) > 1:
        listed = ", ".join(repr(r) for r in roots)
        linter.add(
            robot,
            f"has {len(roots)} root links ({listed}); expected exactly one root link (connect the others with joints)",
            crash_prone=True,
        )
        return
    _reachable_from_root(linter, roots[0], link_names, children_of)


def _unique_names(linter, links: list[ET.Element], joints: list[ET.Element]) -> list[str]:
    """Report unnamed and duplicate links and joints; returns the link names in document order."""
    link_names: list[str] = []
    for index, link in enumerate(links, start=1):
        name = link.get("name")
        if not name:
            linter.add(linter.label("link", link, index), "has no name; expected a unique name")
        else:
            link_names.append(name)
    _report_duplicates(linter, "link", link_names)
    joint_names = [j.get("name") for j in joints if j.get("name")]
    for index, joint in enumerate(joints, start=1):
        if not joint.get("name"):
            linter.add(linter.label("joint", joint, index), "has no name; expected a unique name")
    _report_duplicates(linter, "joint", joint_names)
    return link_names


def _joint_ends(linter, joints: list[ET.Element], known: set[str]) -> tuple[dict[str, list[str]], dict[str, list[str]]]:
    """Report joints whose parent or child link is missing; returns (child link -> its parent
    joints, parent link -> its child links)."""
    parents_of: dict[str, list[str]] = {}
    children_of: dict[str, list[str]] = {}
    for index, joint in enumerate(joints, start=1):
        owner = linter.label("joint", joint, index)
        ends = {}
        for role in ("parent", "child"):
            elem = joint.find(role)
            name = elem.get("link") if elem is not None else None
            if not name:
                linter.add(
                    owner,
                    f"has no <{role} link>; expected the name of a link in this document",
                )
            elif name not in known:
                linter.add(
                    owner,
                    f"{role} link {name!r} does not exist; expected the name of a link in this document",
                )
            else:
                ends[role] = name
        if "child" in ends:
            parents_of.setdefault(ends["child"], []).append(joint.get("name") or owner)
        if "parent" in ends and "child" in ends:
            children_of.setdefault(ends["parent"], []).append(ends["child"])
    return parents_of, children_of


def _reachable_from_root(linter, root_link: str, link_names: list[str], children_of: dict[str, list[str]]) -> None:
    """One root: every link must hang from it (anything else sits on a cycle)."""
    reached = {root_link}
    frontier = [root_link]
    while frontier:
        for child in children_of.get(frontier.pop(), []):
            if child not in reached:
                reached.add(child)
                frontier.append(child)
    for name in dict.fromkeys(link_names):
        if name not in reached:
            linter.add(
                f"link '{name}'",
                f"is not reachable from the root link {root_link!r} (its joints form a "
                f"cycle); expected the links and joints to form a tree",
                crash_prone=True,
            )


def _report_duplicates(linter, kind: str, names: list[str]) -> None:
    counts: dict[str, int] = {}
    for name in names:
        counts[name] = counts.get(name, 0) + 1
    for name, count in counts.items():
        if count > 1:
            linter.add(
                f"{kind} '{name}'",
                f"name is used by {plural(count, kind)}; expected unique {kind} names",
            )

"""Stage 6: the robot as one multibody: tools welded on (:func:`weld_tools`), and its fixed
links merged (:func:`merge_robot`, :func:`.merge.merge_fixed_links`), as the person's are.

**Tools welded on.** The reference holds a tool with a fixed constraint of at most 500 N between
the hand and the tool, a free body: six constraint rows coupling the arm and the tool, solved with
everything else at every physics step, and a body of its own in the collision world. A tool
that nothing presses on stays exactly at its grip, the same rigid attachment as a link of the
hand, so the compiler makes it one: its links join the robot's URDF on a fixed joint at the grip
(``tools[].position``/``orientation`` in the grip link's frame), the manifest marks it
``welded``, and the tool body's ``urdf`` becomes the robot's. The runtime gives it a handle on
those links of the robot's multibody (contacts and distances stay the tool's own). Scratch Itch
steps 1.24× faster with Jaco, its outcomes within noise (``docs/physics.md``).

Only where nothing with weight can press on the tool: the scene has no particles, and every
person and every piece of furniture that can move is weightless (Scratch Itch's seated person,
as in the reference). Under load the constraint is not a rigid attachment: solved at the
reference's 50 iterations it gives way, and that is the reference's physics. In Arm Manipulation
the limp arm squeezes the scooper against the bed; held by the constraint the scooper sinks up to
17 mm into it (max penetration 17 mm against 3.5 mm welded), and the scripted policy succeeds on 15
of 20 seeds against 6 welded. The spoon's food and the cup's water rest in theirs (and against a
link deep in the arm's chain Feeding's step was slower, 0.93×). A tool also stays free when its
gravity differs from the robot's (a link feels its body's gravity) or its friction is set, when a link or joint name of
it is also the robot's, and in a task with a garment (below).

**Fixed links merged.** A robot's URDF keeps many links on fixed joints that the simulation pays
for every physics step and nothing reads: PR2's sensor frames, cameras and gripper palms,
Baxter's head, screen and arm mounts, and every finger the task welds (:mod:`.weld`). Merged into
the link they hang on, their shapes and masses stay (the inertials are combined exactly), so the
dynamics are the same; the robot alone then steps up to twice as fast (PR2; ``docs/physics.md``).

A link survives when the manifest names it anywhere (the robot's roles such as ``tool_mount``,
tool and garment grips, a welded tool's links, the drive's base link, terms' and targets' points)
or when it is the root. The stage runs after the manifest is built, on the robot URDF the earlier
stages (base search, start configurations) used, so every name it could refer to is known; those
stages' results do not change, because the kinematics of the movable joints do not.

Neither happens in a task with a garment. Bullet collides cloth with a rigid link through the
link's own shapes, and a hand with its fingers merged in is a different collider for the cloth
than the hand and fingers as links: the shipped Dressing co-optimised pair's return fell from
−33.7 to −41.8 on 12 paired seeds (``docs/physics.md``). There the robot stays as emitted; the
cloth is most of the step anyway.
"""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from collections.abc import Iterator

import numpy as np

from ..artifact import Manifest, ToolAttachment
from ..errors import SpecError
from ..rotation import quat_matrix
from ..urdf import urdf_info
from .emit import EmittedScene
from .lint import lint_urdf
from .merge import Pose, merge_fixed_links, reindent, write_origin


def weld_tools(manifest: Manifest, scene: EmittedScene) -> Manifest:
    """Weld every tool that can be (see the module docstring) into the scene's robot URDF; returns
    the manifest with those tools ``welded`` and their bodies' ``urdf`` the robot's. Their own
    URDF files are removed from the scene."""
    if manifest.garments:  # the cloth's contacts are per link: see the module docstring
        return manifest
    robot_path = scene.written["robot"]
    robot = ET.fromstring(robot_path.read_text())
    tools = []
    for att in manifest.tools:
        tool = ET.parse(scene.written[att.body]).getroot()
        if _weldable(manifest, att, robot, tool):
            _weld(robot, att, tool)
            scene.written.pop(att.body).unlink()
            att = att.model_copy(update={"welded": True})
        tools.append(att)
    welded = {att.body for att in tools if att.welded}
    if not welded:
        return manifest
    robot_urdf = manifest.body("robot").urdf
    bodies = [b.model_copy(update={"urdf": robot_urdf}) if b.name in welded else b for b in manifest.bodies]
    reindent(robot)
    robot_path.write_text('<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n")
    return manifest.model_copy(update={"tools": tools, "bodies": bodies})


def _weldable(manifest: Manifest, att: ToolAttachment, robot: ET.Element, tool: ET.Element) -> bool:
    """Whether ``att``'s tool can join the robot: nothing with weight can press on it (no particles,
    every person and every piece of furniture that can move weightless), it feels the robot's
    gravity, and none of its link or joint names is the robot's."""
    if manifest.particles:
        return False
    for body in manifest.bodies:
        movable = body.kind == "person" or (body.kind == "furniture" and not body.fixed_base)
        if movable and body.gravity != 0.0:
            return False
    if manifest.body(att.body).gravity != manifest.body("robot").gravity:
        return False
    if manifest.body(att.body).friction is not None:  # its own friction: a link of the robot would have the robot's
        return False
    names = {e.get("name") for e in robot if e.tag in ("link", "joint")}
    return not names & {e.get("name") for e in tool if e.tag in ("link", "joint")} and f"{att.body}_grip" not in names


def _weld(robot: ET.Element, att: ToolAttachment, tool: ET.Element) -> None:
    """Append the tool's links and joints to ``robot`` and a fixed joint ``<tool>_grip`` from the
    grip link to the tool's root at the grip pose. Visual materials are written into each visual
    (named ``<tool>/<material>``), since the robot's document may define the same names otherwise."""
    palette = {m.get("name"): m for m in tool.findall("material")}
    root = att.links["base"]
    for element in tool:
        if element.tag not in ("link", "joint"):
            continue
        element = copy.deepcopy(element)
        for material in element.iter("material"):
            name = material.get("name")
            if not len(material) and name in palette:
                material.extend(copy.deepcopy(list(palette[name])))
            material.set("name", f"{att.body}/{name}")
        robot.append(element)
    grip = ET.SubElement(robot, "joint", {"name": f"{att.body}_grip", "type": "fixed"})
    ET.SubElement(grip, "parent", {"link": att.parent_link})
    ET.SubElement(grip, "child", {"link": root})
    write_origin(grip, Pose(quat_matrix(att.orientation), np.asarray(att.position, dtype=float)))


def merge_robot(manifest: Manifest, scene: EmittedScene) -> list[str]:
    """Rewrite the scene's robot URDF with every link the manifest does not name merged into its
    parent (none in a task with a garment); returns the merged links' names (document order)."""
    if manifest.garments:  # the cloth's contacts are per link: see the module docstring
        return []
    path = scene.written["robot"]
    xml = path.read_text()
    links = set(urdf_info(xml).links)
    keep = {name for name in _names_in(manifest.model_dump(mode="json")) if name in links}
    merged, frames = merge_fixed_links(xml, keep=keep)
    problems = lint_urdf(merged, template=f"merged robot '{manifest.robot_name}'", static_root=True)
    if problems:  # pragma: no cover - the merge preserves validity; lint guards it
        raise SpecError.at(str(path), f"merged robot URDF refused: {problems[0]}")
    path.write_text(merged)
    return list(frames)


def _names_in(value: object) -> Iterator[str]:
    """Every string in a JSON value, and of a dotted one (``robot.tool_mount``) its last part too."""
    if isinstance(value, str):
        yield value
        if "." in value:
            yield value.rsplit(".", 1)[1]
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from _names_in(k)
            yield from _names_in(v)
    elif isinstance(value, list):
        for v in value:
            yield from _names_in(v)

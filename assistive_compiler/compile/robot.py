"""Stage 6: the robot's fixed links merged (:func:`.merge.merge_fixed_links`), as the person's are.

A robot's URDF keeps links on fixed joints that the simulation pays for every physics step and
nothing reads: PR2's sensor frames, cameras and gripper palms, Baxter's head, screen and arm
mounts, and every finger the task welds (:mod:`.weld`). Merged into the link they hang on, their
shapes and masses stay (the inertials are combined exactly), so the dynamics are the same; the
robot alone then steps up to twice as fast (PR2; ``docs/physics.md``).

A link survives when the manifest names it anywhere (the robot's roles such as ``tool_mount``,
tool and garment grips, the drive's base link, terms' and targets' points) or when it is the
root. The stage runs after the manifest is built, on the robot URDF the earlier stages (base
search, start configurations) used, so every name it could refer to is known; those stages'
results do not change, because the kinematics of the movable joints do not.

Not in a task with a garment. Bullet collides cloth with a rigid link through the link's own
shapes, and a hand with its fingers merged in is a different collider for the cloth than the hand
and fingers as links: the shipped Dressing co-optimised pair's return fell from −33.7 to −41.8 on
12 paired seeds (``docs/physics.md``). There the robot stays as emitted; the cloth is most of
the step anyway.
"""

from __future__ import annotations

from collections.abc import Iterator

from ..artifact import Manifest
from ..errors import SpecError
from ..urdf import urdf_info
from .emit import EmittedScene
from .lint import lint_urdf
from .merge import merge_fixed_links


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

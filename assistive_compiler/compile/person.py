"""Stages 4 and 5: the person's merge and its runtime settings.

:func:`merge_people` takes the resolved task and the emitted scene (after placement) and rewrites
each ``person_<variant>.urdf`` with its static links merged into as few rigid links as possible,
keeping the links the task refers to and those self-collision needs; it returns the enabled
self-collision pairs (surviving link names). :func:`finish_person` takes the manifest, the
artifact's temporary directory and those pairs and returns the manifest with the pairs that do not
already touch at rest, and a user's arm-limit model copied into the artifact."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path
from typing import Any

from ..artifact import Manifest
from ..errors import Problem, SpecError
from ..resolve import ResolvedTask
from .emit import EmittedScene
from .lint import lint_urdf
from .merge import merge_fixed_links
from .placement.client import PlacementClient
from .self_collision import person_self_collision
from .task import arm_limits_path, referenced_person_links


def merge_people(rt: ResolvedTask, scene: EmittedScene) -> list[tuple[str, str]]:
    """Merge each person's static links: a seated person with a movable head goes from 43 links to
    5, which is most of a step's physics cost. Returns the self-collision pairs (link names)."""
    variants = rt.spec.person.variants
    keep = referenced_person_links(rt)
    collision_keep, collision_pairs = person_self_collision(scene.written[f"person_{variants[0]}"].read_text(), keep)
    keep |= collision_keep  # links kept so that self-collision stays exact (see person_self_collision)
    for variant in variants:
        path = scene.written[f"person_{variant}"]
        merged, _frames = merge_fixed_links(path.read_text(), keep=keep)
        problems = lint_urdf(merged, template=f"merged person '{variant}'")
        if problems:  # pragma: no cover - the merge preserves validity; lint guards it
            raise SpecError(
                [
                    Problem(rt.loaded.smap.value(("person", "variants")), f"merged person URDF refused: {pr}")
                    for pr in problems
                ]
            )
        path.write_text(merged)
    return collision_pairs


def finish_person(rt: ResolvedTask, manifest: Manifest, out_tmp: Path, pairs: list[tuple[str, str]]) -> Manifest:
    """The person's runtime settings that need the merged bodies or extra files: the self-collision
    pairs minus those already touching (within 1 mm) at a variant's initial pose — shapes that
    overlap at rest, such as the upper arm and the chest capsule, would otherwise push each other
    apart at every reset — and the arm-limit model (a user's .npz is copied into the artifact)."""
    update: dict[str, Any] = {}
    if pairs:
        update["self_collision"] = _pairs_apart_at_rest(rt, manifest, out_tmp, pairs)
    setting = rt.spec.person.control.arm_limits
    if setting not in ("none", "analytic"):
        update |= _copy_arm_limits(rt, out_tmp)
    if not update:
        return manifest
    return manifest.model_copy(update={"person": manifest.person.model_copy(update=update)})


def _pairs_apart_at_rest(
    rt: ResolvedTask, manifest: Manifest, out_tmp: Path, pairs: list[tuple[str, str]]
) -> list[tuple[str, str]]:
    """``pairs`` less those within 1 mm at any variant's initial pose (merged bodies, fixed base)."""
    import pybullet

    pc = PlacementClient(rt.spec.sim.solver.contact_breaking_threshold_m)
    try:
        p, c = pc.p, pc.client
        touching: set[tuple[str, str]] = set()
        for variant in manifest.person.variants:
            body = manifest.body(variant.body)
            bid = p.loadURDF(
                str(out_tmp / body.urdf), useFixedBase=True, flags=pybullet.URDF_USE_SELF_COLLISION, physicsClientId=c
            )
            joints = pc.joint_index(bid)
            for name, q in variant.initial_angles.items():
                p.resetJointState(bid, joints[name], q, physicsClientId=c)
            for a, b in pairs:
                if p.getClosestPoints(bid, bid, 0.001, pc.link_index(bid, a), pc.link_index(bid, b), physicsClientId=c):
                    touching.add((a, b))
    finally:
        pc.close()
    return [pair for pair in pairs if pair not in touching]


def _copy_arm_limits(rt: ResolvedTask, out_tmp: Path) -> dict[str, Any]:
    """Check and copy a user's arm-limit network into the artifact; its manifest fields."""
    from ..person.arm_limits import MLPArmLimits

    where = rt.loaded.smap.value(("person", "control", "arm_limits"))
    source = arm_limits_path(rt.loaded)
    try:
        MLPArmLimits.from_npz(source)
    except ValueError as exc:
        raise SpecError([Problem(where, f"person.control.arm_limits: {exc}")]) from None
    shutil.copyfile(source, out_tmp / "arm_limits.npz")
    return {"arm_limits": "arm_limits.npz", "arm_limits_sha256": hashlib.sha256(source.read_bytes()).hexdigest()}

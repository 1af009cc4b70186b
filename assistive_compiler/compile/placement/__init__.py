"""Stage 3: compile-time physics placement, in a private pybullet DIRECT client — the only place
the compiler steps physics.

:func:`precompute` takes the resolved task, the emitted (unmerged) scene and the artifact's
temporary directory, and returns the manifest without hashes: every body's pose, the robot's base
poses and start configurations per person variant, the settled particles and garments. Modules:

- :mod:`.client` — the private client and its queries;
- :mod:`.scene` — loading the emitted bodies at their nominal poses;
- :mod:`.ik` — arm IK with collision checks, JLWKI;
- :mod:`.base_search` — the base-pose search and furniture carried under a searched base;
- :mod:`.starts` — per person variant: base poses, then start configurations;
- :mod:`.settle_person`, :mod:`.settle_particles`, :mod:`.settle_garment` — letting bodies come
  to rest (the person's settle runs earlier, before the person's URDF is emitted).
"""

from __future__ import annotations

from pathlib import Path

from ...artifact import Manifest
from ...resolve import ResolvedTask
from ..emit import EmittedScene
from ..manifest import build_manifest, person_variant
from .client import PlacementClient
from .ik import arm_chains
from .scene import load_scene
from .settle_garment import settle_garment
from .settle_particles import settle_particles
from .starts import place_for_variant, pose_at_first_start


def precompute(rt: ResolvedTask, emitted: EmittedScene, out_tmp: Path) -> Manifest:
    """Place everything (see the module docstring); the manifest's paths are relative to ``out_tmp``."""
    spec = rt.spec
    pc = PlacementClient(spec.sim.solver.contact_breaking_threshold_m)
    try:
        scene = load_scene(rt, pc, emitted, out_tmp)
        arms = arm_chains(rt, pc, scene)
        _, start, tool_orn = arms[0]
        placed = {variant: place_for_variant(rt, pc, scene, arms, variant) for variant in spec.person.variants}
        variants = [
            person_variant(
                rt,
                v,
                emitted.written[f"person_{v}"],
                emitted.measurements[v],
                emitted.postures[v],
                emitted.movable,
                starts,
            )
            for v, (starts, _) in placed.items()
        ]
        robot = pose_at_first_start(rt, pc, scene, arms, variants[0].starts[0])
        particles = [settle_particles(rt, pc, name, ps, scene, start, tool_orn) for name, ps in spec.particles.items()]
        garments = [
            settle_garment(rt, name, g, out_tmp, scene.garment_grips[name], tool_orn)
            for name, g in spec.garments.items()
        ]
    finally:
        pc.close()
    return build_manifest(
        rt,
        bodies=[robot, *scene.bodies],
        variants=variants,
        tools=scene.attachments,
        particles=particles,
        garments=garments,
        arm_joints=scene.arm_joints,
        lower=scene.lower,
        upper=scene.upper,
        placements={v: placement for v, (_, placement) in placed.items()},
        welded=emitted.welded,
    )

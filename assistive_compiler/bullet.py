"""The one way the package opens a pybullet client (runtime worlds and the compiler's private
precompute sessions alike), and the engine setting pybullet keeps per process, not per client.

**Contact breaking threshold** (a task's ``sim.solver.contact_breaking_threshold_m``; Bullet's
default 0.02 m). A persistent contact manifold keeps an old contact point until it drifts this
far. A rolling 5 mm food or water particle, whose contact point moves over its own surface every
step, so piles up near-copies of its one contact (23 points for 8 particles in a spoon), each a
solver row; at 2 mm they are dropped within a step or two (Feeding's physics: 14% fewer
instructions, Drinking's: 21%). But the value changes the contacts themselves (how deep food and
water sink, docs/physics.md), and stale points widen where a contact is reported, which Bed
Bathing's wiping counts: every shipped task keeps Bullet's default, as the reference does.

pybullet stores this threshold in one process-wide variable, read when a contact manifold is
created. So it is set when a client opens and again before every env step of a world
(:func:`use_contact_breaking_threshold`, about a microsecond): envs of different tasks can share a
process, and each still simulates with its own value, whatever ran before.
"""

from __future__ import annotations

import pybullet as pb

#: Bullet's own default contact breaking threshold, m.
BULLET_DEFAULT_CONTACT_BREAKING_THRESHOLD_M = 0.02


def connect(
    contact_breaking_threshold: float = BULLET_DEFAULT_CONTACT_BREAKING_THRESHOLD_M, deformable: bool = False
) -> int:
    """A new DIRECT client using ``contact_breaking_threshold`` (m); ``deformable``: Bullet's
    deformable world (soft bodies), which must be chosen before anything is loaded. Returns a
    negative id when pybullet cannot connect."""
    client = pb.connect(pb.DIRECT)
    if client < 0:
        return client
    if deformable:
        pb.resetSimulation(pb.RESET_USE_DEFORMABLE_WORLD, physicsClientId=client)
    use_contact_breaking_threshold(client, contact_breaking_threshold)
    return client


def use_contact_breaking_threshold(client: int, value: float) -> None:
    """Make ``value`` (m) the process's contact breaking threshold (see the module docstring)."""
    pb.setPhysicsEngineParameter(contactBreakingThreshold=value, physicsClientId=client)

"""`assistive_compiler.bullet`: the contact breaking threshold, which pybullet keeps per process.
A 5 mm ball rolling across a floor keeps exactly one contact point at 2 mm (what Feeding and
Drinking ask for), while Bullet's default 2 cm keeps a stale copy of it (a second solver row).
Two clients with different thresholds in one process each get their own, because the value is
set again before stepping (as ``World.step_physics`` does every env step)."""

from __future__ import annotations

import pybullet as pb

from assistive_compiler.bullet import (
    BULLET_DEFAULT_CONTACT_BREAKING_THRESHOLD_M,
    connect,
    use_contact_breaking_threshold,
)


def _rolling_ball(client: int) -> int:
    pb.setGravity(0, 0, -9.81, physicsClientId=client)
    pb.setTimeStep(0.02, physicsClientId=client)
    floor = pb.createMultiBody(
        0,
        pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[0.5, 0.5, 0.05], physicsClientId=client),
        -1,
        [0, 0, -0.05],
        physicsClientId=client,
    )
    ball = pb.createMultiBody(
        0.001,
        pb.createCollisionShape(pb.GEOM_SPHERE, radius=0.005, physicsClientId=client),
        -1,
        [0, 0, 0.005],
        physicsClientId=client,
    )
    pb.resetBaseVelocity(ball, [0.05, 0, 0], [0, 10.0, 0], physicsClientId=client)  # rolling at 5 cm/s
    return floor * 1000 + ball


def _roll(client: int, bodies: int, threshold: float, steps: int = 20) -> tuple[list[int], float]:
    floor, ball = divmod(bodies, 1000)
    counts = []
    for _ in range(steps):
        use_contact_breaking_threshold(client, threshold)
        pb.stepSimulation(physicsClientId=client)
        counts.append(len(pb.getContactPoints(ball, floor, physicsClientId=client)))
    return counts, pb.getBasePositionAndOrientation(ball, physicsClientId=client)[0][0]


def test_each_client_rolls_with_its_own_threshold():
    small, default = connect(0.002), connect()
    try:
        a, b = _rolling_ball(small), _rolling_ball(default)
        counts_small, counts_default = [], []
        for _ in range(4):  # interleaved, as envs of two tasks in one process
            counts_small += _roll(small, a, 0.002, 5)[0]
            counts_default += _roll(default, b, BULLET_DEFAULT_CONTACT_BREAKING_THRESHOLD_M, 5)[0]
        x = pb.getBasePositionAndOrientation(divmod(a, 1000)[1], physicsClientId=small)[0][0]
    finally:
        pb.disconnect(small)
        pb.disconnect(default)
    assert counts_small == [1] * 20
    assert max(counts_default) == 2  # the stale copy
    assert 0.015 < x < 0.05  # it did roll (about 2 cm in 0.4 s), on the floor throughout

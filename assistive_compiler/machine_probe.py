"""How fast this machine runs pybullet right now: a fixed workload, to carry a speed figure taken
on one day over to another.

``bench`` divides our env steps/s by the reference implementation's, which can only be measured
side by side with the reference harness (the reference's own source, its own environment). On a
shared machine the same two programs run anywhere from 1× to 2× slower from one day to the next
(load, frequency scaling, neighbours on the host), both alike. A stored reference figure is
therefore only meaningful next to a measure of the machine's speed in the same session: the probe.
It runs beside the harness when the reference figures are taken, and again inside every ``bench``,
which scales the stored figure by ``now / then``.

The workload looks like an assistive env step and nothing in it is ours, so that a change to our
code never changes the probe: a 7-joint fixed-base arm under position control driven along a
sine, a free box held to its hand by a fixed constraint, a pile of free boxes resting on a
table (about 25 contact points), at PyBullet's default 50 solver iterations and a 20 ms time step; per
probe step one motor command, five ``stepSimulation`` calls, a link-state read and a contact query.
Changing the workload invalidates every stored figure measured against it: bump
:data:`PROBE_VERSION` and measure them again.
"""

from __future__ import annotations

import math
import statistics
import time

import pybullet as pb

PROBE_VERSION = 1
"""Which workload :func:`probe_steps_per_s` runs; stored figures name the version they were taken with."""

_ARM_JOINTS = 7
_LINK_LENGTH_M = 0.12
_PILE = 6


def _build(client: int) -> tuple[int, list[int]]:
    """The probe's scene; returns the arm's body id and its joint indices."""
    c = client
    pb.setGravity(0, 0, -9.81, physicsClientId=c)
    pb.setTimeStep(0.02, physicsClientId=c)
    pb.setPhysicsEngineParameter(numSolverIterations=50, deterministicOverlappingPairs=1, physicsClientId=c)
    table = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[0.6, 0.6, 0.05], physicsClientId=c)
    pb.createMultiBody(0, table, -1, [0.3, 0, 0.35], physicsClientId=c)
    capsule = pb.createCollisionShape(
        pb.GEOM_CAPSULE,
        radius=0.03,
        height=_LINK_LENGTH_M,
        collisionFramePosition=[0, 0, _LINK_LENGTH_M / 2],
        physicsClientId=c,
    )
    base = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[0.05, 0.05, 0.05], physicsClientId=c)
    axes = [[0, 0, 1], [0, 1, 0]] * 4
    arm = pb.createMultiBody(
        baseMass=0,
        baseCollisionShapeIndex=base,
        basePosition=[0, 0, 0.45],
        linkMasses=[1.0] * _ARM_JOINTS,
        linkCollisionShapeIndices=[capsule] * _ARM_JOINTS,
        linkVisualShapeIndices=[-1] * _ARM_JOINTS,
        linkPositions=[[0, 0, 0.05]] + [[0, 0, _LINK_LENGTH_M]] * (_ARM_JOINTS - 1),
        linkOrientations=[[0, 0, 0, 1]] * _ARM_JOINTS,
        linkInertialFramePositions=[[0, 0, _LINK_LENGTH_M / 2]] * _ARM_JOINTS,
        linkInertialFrameOrientations=[[0, 0, 0, 1]] * _ARM_JOINTS,
        linkParentIndices=list(range(_ARM_JOINTS)),
        linkJointTypes=[pb.JOINT_REVOLUTE] * _ARM_JOINTS,
        linkJointAxis=axes[:_ARM_JOINTS],
        physicsClientId=c,
    )
    box = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[0.04, 0.04, 0.04], physicsClientId=c)
    held = pb.createMultiBody(0.3, box, -1, [0, 0, 0.45 + 0.05 + _ARM_JOINTS * _LINK_LENGTH_M], physicsClientId=c)
    pb.createConstraint(
        arm, _ARM_JOINTS - 1, held, -1, pb.JOINT_FIXED, [0, 0, 0], [0, 0, _LINK_LENGTH_M], [0, 0, 0], physicsClientId=c
    )
    for k in range(_PILE):
        pb.createMultiBody(0.2, box, -1, [0.45 + 0.09 * (k % 3), -0.1 + 0.2 * (k // 3), 0.45], physicsClientId=c)
    joints = list(range(_ARM_JOINTS))
    pb.setJointMotorControlArray(arm, joints, pb.VELOCITY_CONTROL, forces=[0.0] * _ARM_JOINTS, physicsClientId=c)
    return arm, joints


def _drive(client: int, arm: int, joints: list[int], steps: int) -> None:
    """``steps`` probe steps from the current state: the arm's targets along a sine, five physics
    steps, the hand's links read, the contacts queried."""
    c = client
    for k in range(steps):
        phase = 2 * math.pi * k / 50
        targets = [0.6 * math.sin(phase + j) + (0.9 if j == 1 else 0.0) for j in joints]
        pb.setJointMotorControlArray(
            arm,
            joints,
            pb.POSITION_CONTROL,
            targetPositions=targets,
            positionGains=[0.05] * len(joints),
            forces=[50.0] * len(joints),
            physicsClientId=c,
        )
        for _ in range(5):
            pb.stepSimulation(physicsClientId=c)
        pb.getLinkStates(arm, joints, physicsClientId=c)
        pb.getContactPoints(physicsClientId=c)


def probe_steps_per_s(steps: int = 150, repeats: int = 5) -> float:
    """Probe steps per second (each: one motor command, five physics steps, two reads), the median
    over ``repeats`` runs of ``steps`` from the same saved state, timed by the wall clock."""
    c = pb.connect(pb.DIRECT)
    try:
        arm, joints = _build(c)
        start = pb.saveState(physicsClientId=c)
        rates = []
        for _ in range(repeats):
            pb.restoreState(start, physicsClientId=c)
            t0 = time.perf_counter()
            _drive(c, arm, joints, steps)
            rates.append(steps / (time.perf_counter() - t0))
        return statistics.median(rates)
    finally:
        pb.disconnect(c)


def probe_fingerprint(steps: int = 150) -> tuple[tuple[float, float, float], int]:
    """What the workload does, to tell when it changed: the hand's world position (m, rounded to
    0.1 mm) and the number of contact points after ``steps`` probe steps from the start."""
    c = pb.connect(pb.DIRECT)
    try:
        arm, joints = _build(c)
        _drive(c, arm, joints, steps)
        hand = pb.getLinkState(arm, joints[-1], physicsClientId=c)[0]
        return tuple(round(x, 4) for x in hand), len(pb.getContactPoints(physicsClientId=c))  # type: ignore[return-value]
    finally:
        pb.disconnect(c)

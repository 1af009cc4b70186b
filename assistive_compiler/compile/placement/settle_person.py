"""Settling a supine person onto the furniture (``person.placement.settle``; paper §III-B).

:func:`settle_people` takes the resolved task and the scene emitted so far (robot, furniture)
and returns, per person variant, the settled base pose of the URDF frame (position m,
quaternion x, y, z, w; world frame) and every joint's angle (rad), all rounded for the manifest
— or ``{}`` when the task does not settle its person. Each variant settles in a private client
of its own, deterministically per (task, robot, variant)."""

from __future__ import annotations

import math

import numpy as np

from ...library import PERSON_TEMPLATE_RELPATH
from ...paths import templates_dir
from ...resolve import ResolvedTask
from ...rotation import quat_from_rpy_deg
from ...templates import expand_template
from ..emit import EmittedScene, person_xacro_args
from ..task import fail, group_joints, present_furniture, rounded, seed
from .client import PlacementClient


def settle_people(rt: ResolvedTask, scene: EmittedScene) -> dict[str, tuple[tuple, tuple, dict[str, float]]]:
    """Variant -> (base position, base orientation, joint angles) after settling; ``{}`` without a settle."""
    person = rt.spec.person
    if not person.placement.settle:
        return {}
    return {variant: settle_person(rt, scene, variant) for variant in person.variants}


def settle_person(rt: ResolvedTask, scene: EmittedScene, variant: str) -> tuple[tuple, tuple, dict[str, float]]:
    """Drop the limp person onto the furniture (paper §III-B): every joint free and perturbed by
    U(±joint_noise_rad) around the spec's posture, a free base at the placement pose, the settle
    gravity and furniture friction, ``steps`` physics steps. Returns the settled base pose (URDF
    frame) and joint angles (rad). Deterministic per (task, robot, variant)."""
    spec = rt.spec
    settle = spec.person.placement.settle
    pc = PlacementClient(rt.spec.sim.solver.contact_breaking_threshold_m)
    p, c = pc.p, pc.client
    try:
        p.setTimeStep(spec.sim.time_step_s, physicsClientId=c)
        p.setGravity(0, 0, settle.gravity_mps2, physicsClientId=c)
        p.setPhysicsEngineParameter(
            numSolverIterations=spec.sim.solver.iterations,
            numSubSteps=spec.sim.solver.sub_steps,
            deterministicOverlappingPairs=1,
            physicsClientId=c,
        )
        p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, physicsClientId=c), physicsClientId=c)
        for name, use in present_furniture(rt, placed_only=True).items():
            fid = pc.load(scene.written[name], use.position_m, quat_from_rpy_deg(use.rpy_deg), True)
            if settle.friction is not None:
                pc.set_friction(fid, settle.friction)
        body = _load_limp(rt, pc, scene, variant)
        rng = np.random.default_rng(seed(rt, variant) ^ 0x5E771E)
        joints = pc.joint_index(body)
        names = [j for j in rt.person_urdf.movable_joints]
        for name in names:
            info = rt.person_urdf.movable_joints[name]
            q = math.radians(spec.person.joints_deg.get(name, 0.0)) + rng.uniform(
                -settle.joint_noise_rad, settle.joint_noise_rad
            )
            p.resetJointState(body, joints[name], min(max(q, info.lower), info.upper), physicsClientId=c)
        idx = [joints[n] for n in names]
        p.setJointMotorControlArray(body, idx, p.VELOCITY_CONTROL, forces=[0.0] * len(idx), physicsClientId=c)
        for _ in range(settle.steps):
            p.stepSimulation(physicsClientId=c)
        pos, orn = pc.link_pose(body, -1)
        angles = {n: s[0] for n, s in zip(names, p.getJointStates(body, idx, physicsClientId=c))}
        if settle.then is not None:
            angles = _settle_stage(rt, pc, body, joints, names, angles)
        if not all(math.isfinite(v) for v in [*pos, *orn, *angles.values()]) or abs(pos[2]) > 10:
            raise fail(
                rt,
                ("person", "placement", "settle"),
                f"person '{variant}' did not settle (the body left the scene); check placement.position_m",
            )
        return rounded(tuple(pos)), rounded(tuple(orn)), {n: rounded(a) for n, a in angles.items()}
    finally:
        pc.close()


def _load_limp(rt: ResolvedTask, pc: PlacementClient, scene: EmittedScene, variant: str) -> int:
    """Load the person with every joint free (nothing baked), its base frame at the placement pose."""
    args = person_xacro_args(scene.measurements[variant], rt.people[variant].part, "")
    limp = scene.urdf_dir / f".settle_{variant}.urdf"
    limp.write_text(expand_template(templates_dir() / PERSON_TEMPLATE_RELPATH, args))
    placement = rt.spec.person.placement
    orn = quat_from_rpy_deg(placement.rpy_deg)
    body = pc.load(limp, (0, 0, 0), orn, False)
    limp.unlink()
    pc.place(body, tuple(placement.position_m), orn)
    return body


def _settle_stage(
    rt: ResolvedTask, pc: PlacementClient, body: int, joints: dict[str, int], names: list[str], angles: dict[str, float]
) -> dict[str, float]:
    """The settle's second stage (``placement.settle.then``): the settled base is fixed where it lies
    and every joint held stiffly at its settled angle, except the stage's dynamic joint groups,
    which are set to the stage's ``joints_deg`` and then move under the stage's gravity and weak
    hold (the reference's arm manipulation: the right arm raised, then dropped to hang off the bed
    for 100 steps at g −9.81). Returns every joint's angle afterwards (rad)."""
    stage = rt.spec.person.placement.settle.then
    p, c = pc.p, pc.client
    dynamic = group_joints(rt, stage.dynamic)
    start = dict(angles) | {j: math.radians(a) for j, a in stage.joints_deg.items()}
    com_pos, com_orn = p.getBasePositionAndOrientation(body, physicsClientId=c)
    p.createConstraint(
        body, -1, -1, -1, p.JOINT_FIXED, (0, 0, 0), (0, 0, 0), com_pos, (0, 0, 0, 1), com_orn, physicsClientId=c
    )
    p.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0), physicsClientId=c)
    for n in names:
        p.resetJointState(body, joints[n], start[n], 0.0, physicsClientId=c)
    held = [n for n in names if n not in dynamic]
    p.setJointMotorControlArray(
        body,
        [joints[n] for n in held],
        p.POSITION_CONTROL,
        targetPositions=[start[n] for n in held],
        forces=[1e4] * len(held),
        physicsClientId=c,
    )
    if stage.hold is not None and dynamic:
        p.setJointMotorControlArray(
            body,
            [joints[n] for n in dynamic],
            p.POSITION_CONTROL,
            targetPositions=[start[n] for n in dynamic],
            positionGains=[stage.hold.position_gain] * len(dynamic),
            forces=[stage.hold.max_force_nm] * len(dynamic),
            physicsClientId=c,
        )
    if stage.friction is not None:
        for bid in range(p.getNumBodies(physicsClientId=c)):
            if bid != body:
                pc.set_friction(bid, stage.friction)
    p.setGravity(0, 0, stage.gravity_mps2, physicsClientId=c)
    for _ in range(stage.steps):
        p.stepSimulation(physicsClientId=c)
        for n in held:  # static joints stay exactly where they settled
            p.resetJointState(body, joints[n], start[n], 0.0, physicsClientId=c)
    idx = [joints[n] for n in names]
    return {n: s[0] for n, s in zip(names, p.getJointStates(body, idx, physicsClientId=c))}

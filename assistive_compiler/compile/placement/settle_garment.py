"""Settling a garment (a generated sleeve) hanging from the robot's grip.

:func:`settle_garment` takes the task, the garment's name and spec, the artifact's temporary
directory, its grip (the holding hand's tool-mount link, grip position m, grip orientation) and
the held frame's start orientation (x, y, z, w); it writes the sleeve's mesh to
``garments/<name>.obj`` (vertices in the held frame, m), lets it hang in a deformable world of
its own, and returns the :class:`Garment` manifest entry with the settled nodes (held frame, m)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...artifact import Garment
from ...bullet import connect
from ...resolve import ResolvedTask
from ...rotation import quat_from_rpy_deg, quat_matrix
from ..task import fail, rounded


def settle_garment(rt: ResolvedTask, name: str, g, out_tmp: Path, grip, held_orn) -> Garment:
    """Generate a garment's mesh into the artifact (vertices in the held frame) and let it hang
    from the held frame — at the task's start orientation, away from everything — for
    ``settle.steps`` physics steps under ``settle.gravity_mps2`` in a deformable world with the
    task's time step and sub-steps. Returns its manifest entry with the settled nodes (held frame).
    Deterministic: the same inputs give the same bytes."""
    import pybullet as pb

    from ...garment import load_garment, sleeve_mesh, sleeve_node_sets, write_obj

    spec, shape, phys = rt.spec, g.shape, g.physics
    verts, faces = sleeve_mesh(shape.length_m, shape.radius_open_m, shape.radius_end_m, shape.rings, shape.segments)
    pose_q = quat_from_rpy_deg(g.held.rpy_deg)
    rot = quat_matrix(pose_q)
    held_verts = verts @ rot.T + np.asarray(g.held.offset_m)
    obj = out_tmp / "garments" / f"{name}.obj"
    obj.parent.mkdir(exist_ok=True)
    write_obj(obj, np.round(held_verts, 6), faces, name=name)
    sets = {k: [int(i) for i in v] for k, v in sleeve_node_sets(shape.rings, shape.segments).items()}
    anchored = sets[g.held.nodes]
    c = connect(spec.sim.solver.contact_breaking_threshold_m, deformable=True)
    try:
        pb.setTimeStep(spec.sim.time_step_s, physicsClientId=c)
        pb.setPhysicsEngineParameter(numSubSteps=spec.sim.solver.sub_steps, physicsClientId=c)
        pb.setGravity(0, 0, g.settle.gravity_mps2, physicsClientId=c)
        held_pos = (0.0, 0.0, 2.0 + shape.length_m)
        sb, anchor = load_garment(
            pb,
            c,
            obj,
            held_pos,
            held_orn,
            phys.mass_kg,
            phys.collision_margin_m,
            phys.elastic_stiffness,
            phys.damping_stiffness,
            phys.bending_stiffness,
            phys.friction,
            anchored,
        )
        for _ in range(g.settle.steps):
            pb.stepSimulation(physicsClientId=c)
        world = np.asarray(
            pb.getMeshData(sb, -1, flags=pb.MESH_DATA_SIMULATION_MESH, physicsClientId=c)[1], dtype=float
        )
    finally:
        pb.disconnect(c)
    inv_rot = quat_matrix(held_orn).T
    local = (world - np.asarray(held_pos)) @ inv_rot.T
    if not np.all(np.isfinite(local)) or np.abs(local).max() > 5 * (shape.length_m + shape.radius_open_m):
        raise fail(
            rt,
            ("garments", name, "physics"),
            f"garment '{name}' blew up while settling (nodes left the scene): the springs are "
            f"integrated explicitly, so raise sim.solver.sub_steps (now {spec.sim.solver.sub_steps}) or lower physics.elastic_stiffness",
        )
    parent, gpos, gorn = grip
    return Garment(
        name=name,
        obj=str(obj.relative_to(out_tmp)),
        parent_link=parent,
        grip_position=gpos,
        grip_orientation=gorn,
        anchored=anchored,
        node_sets=sets,
        nodes_in_held=[rounded(tuple(v)) for v in local],
        mass=phys.mass_kg,
        collision_margin=phys.collision_margin_m,
        elastic_stiffness=phys.elastic_stiffness,
        damping_stiffness=phys.damping_stiffness,
        bending_stiffness=phys.bending_stiffness,
        friction=phys.friction,
        collides_with=list(g.collides_with) if g.collides_with is not None else None,
        rgba=tuple(g.rgba),
    )

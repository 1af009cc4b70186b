"""Settling each particle set in its container (``particles:`` of a task: the spoon's and
cup's contents).

:func:`settle_particles` takes the task, the placement client (its bodies at the first start),
a particle set's name and spec, the loaded scene and the robot's start (start pose, tool
orientation); it drops the grid of spheres into the holder (the tool at its start pose, or a
piece of furniture), steps ``settle_steps`` and returns the :class:`ParticleSet` manifest entry:
rest positions in the holder link's frame (m, rounded), the consumed, lost and resting rules."""

from __future__ import annotations

import math

import numpy as np

from ...artifact import Container, ParticleRest, ParticleSet
from ...errors import SpecError
from ...resolve import ResolvedTask
from ..task import rounded
from .client import PlacementClient


def settle_particles(rt: ResolvedTask, pc: PlacementClient, name: str, ps, scene, start, tool_orn) -> ParticleSet:
    """Settle particle set ``name`` (spec ``ps``) in its holder; returns its manifest entry."""
    if ps.attach in scene.tools:
        holder = scene.tools[ps.attach]
        pc.place(holder, start.tool_position_m, tool_orn)
        attach_link = rt.tools[ps.attach].part.base_link
    else:
        holder = scene.furniture[ps.attach]
        attach_link = rt.furniture[ps.attach].part.base_link
    frame_pos, frame_orn = pc.named_link_pose(holder, attach_link)
    positions = _drop_grid(pc, ps, frame_pos, frame_orn)
    lost_link, anchor = None, (0.0, 0.0, 0.0)
    if ps.lost_beyond:
        body = ps.lost_beyond.body
        part = rt.tools[body].part if body in rt.tools else rt.furniture[body].part
        lost_link = part.base_link
        anchor = _inside_point(pc, scene.tools.get(body, scene.furniture.get(body)), lost_link)
    colors = [tuple(ps.colors_rgba[i % len(ps.colors_rgba)]) for i in range(ps.count)]
    return ParticleSet(
        name=name,
        count=ps.count,
        radius=ps.radius_m,
        mass=ps.mass_kg,
        attach=ps.attach,
        attach_link=attach_link,
        start_positions=positions,
        colors=colors,
        consumed_target=ps.consumed_at.target if ps.consumed_at else None,
        consumed_radius=ps.consumed_at.radius_m if ps.consumed_at else 0.0,
        lost_body=ps.lost_beyond.body if ps.lost_beyond else None,
        lost_link=lost_link,
        lost_distance=ps.lost_beyond.distance_m if ps.lost_beyond else 0.0,
        lost_anchor=rounded(anchor),
        hit_body=ps.hit_body,
        outside_of=_container(rt, ps.consumed_at.outside_of if ps.consumed_at else None),
        rest=None
        if ps.rest is None
        else ParticleRest(
            container=_container(rt, ps.rest.container),
            max_tilt=math.radians(ps.rest.max_tilt_deg),
            max_turn=math.radians(ps.rest.max_turn_deg),
            max_speed=ps.rest.max_speed_mps,
            still_steps=ps.rest.still_steps,
            carry_at_reset=ps.rest.carry_at_reset,
            near_body=ps.rest.simulated_near.body if ps.rest.simulated_near else None,
            near_distance=ps.rest.simulated_near.distance_m if ps.rest.simulated_near else 0.0,
        ),
    )


def _drop_grid(pc: PlacementClient, ps, frame_pos, frame_orn) -> list[tuple]:
    """Spheres on the set's grid (in the holder frame), stepped ``settle_steps``, then removed;
    their rest positions in the holder frame (m, rounded)."""
    p, c = pc.p, pc.client
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=ps.radius_m, physicsClientId=c)
    ids = []
    for i in range(ps.grid[0]):
        for j in range(ps.grid[1]):
            for k in range(ps.grid[2]):
                local = np.asarray(ps.offset_m) + ps.spacing_m * np.array([i, j, k])
                world, _ = p.multiplyTransforms(frame_pos, frame_orn, tuple(local), (0, 0, 0, 1))
                ids.append(p.createMultiBody(ps.mass_kg, shape, -1, world, physicsClientId=c))
    for _ in range(ps.settle_steps):
        p.stepSimulation(physicsClientId=c)
    inv = p.invertTransform(frame_pos, frame_orn)
    positions = []
    for b in ids:
        world, _ = p.getBasePositionAndOrientation(b, physicsClientId=c)
        local, _ = p.multiplyTransforms(inv[0], inv[1], world, (0, 0, 0, 1))
        positions.append(rounded(tuple(local), 6))
        p.removeBody(b, physicsClientId=c)
    return positions


def _container(rt: ResolvedTask, tool: str | None) -> Container | None:
    if tool is None:
        return None
    part = rt.tools[tool].part
    return Container(body=tool, link=part.base_link, radius=part.container.radius_m, height=part.container.height_m)


def _inside_point(pc: PlacementClient, body: int, link_name: str) -> tuple[float, float, float]:
    """The centre of the link's first collision primitive, in the link frame: inside its geometry."""
    p, c = pc.p, pc.client
    link = pc.link_index(body, link_name)
    shapes = p.getCollisionShapeData(body, link, physicsClientId=c)
    if not shapes:
        raise SpecError.at(link_name, f"link '{link_name}' has no collision geometry to keep particles near")
    local_pos = shapes[0][5]  # in the link's inertial (COM) frame
    inertial_pos, inertial_orn = p.getDynamicsInfo(body, link, physicsClientId=c)[3:5]
    pos, _ = p.multiplyTransforms(inertial_pos, inertial_orn, local_pos, (0, 0, 0, 1))
    return tuple(pos)

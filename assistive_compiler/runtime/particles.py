"""Particle lifecycles (food, water): active → consumed (reached the target) | lost (left its
container); the first contact of an active particle with ``hit_body`` counts once as a hit.

Removed particles are parked far away, apart from each other, at rest and without gravity
compensation, so they touch nothing; they come back at reset. Nothing else about them changes: a
mass of 0 would make them static objects for good, and changing collision filters re-inserts
them in the broadphase, which reorders contact pairs — either would make an episode depend on the
ones before it. Events are evaluated once per env step, as in the reference.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb

from ..artifact import ParticleSet
from .snapshot import ParticleEvents, PointHandle, Snapshot
from .world import PARK, World


class ParticleSystem:
    """All particle sets of a world."""

    def __init__(self, world: World, snap: Snapshot):
        self.world = world
        self.snap = snap
        self.sets: list[tuple[ParticleSet, list[int], PointHandle | None]] = []
        for ps in world.m.particles:
            target = snap.point({"target": ps.consumed_target}) if ps.consumed_target else None
            self.sets.append((ps, world.particles[ps.name], target))
        self.active: dict[str, np.ndarray] = {}
        self.hit: dict[str, np.ndarray] = {}

    def reset(self) -> None:
        """Place every particle at its settled position in its holder's frame; all active."""
        w, c = self.world, self.world.client
        for ps, ids, _ in self.sets:
            holder = w.bodies[ps.attach]
            frame_pos, frame_orn = w.link_frame(holder, holder.links[ps.attach_link])
            for pid, local in zip(ids, ps.start_positions):
                w.parked.discard(pid)
                pos, _ = pb.multiplyTransforms(frame_pos, frame_orn, local, (0, 0, 0, 1))
                pb.resetBasePositionAndOrientation(pid, pos, (0, 0, 0, 1), physicsClientId=c)
                pb.resetBaseVelocity(pid, (0, 0, 0), (0, 0, 0), physicsClientId=c)
            self.active[ps.name] = np.ones(ps.count, dtype=bool)
            self.hit[ps.name] = np.zeros(ps.count, dtype=bool)
            self.snap.events[ps.name] = ParticleEvents()

    def _park(self, pid: int, k: int) -> None:
        c = self.world.client
        pb.resetBasePositionAndOrientation(pid, (PARK[0] - 5.0 - 0.1 * k, PARK[1], PARK[2]), (0, 0, 0, 1), physicsClientId=c)
        pb.resetBaseVelocity(pid, (0, 0, 0), (0, 0, 0), physicsClientId=c)
        self.world.parked.add(pid)

    def update(self) -> None:
        """Evaluate this step's events (after physics, after the snapshot refresh)."""
        w, c, snap = self.world, self.world.client, self.snap
        base_pose, base_velocity, closest = pb.getBasePositionAndOrientation, pb.getBaseVelocity, pb.getClosestPoints
        for ps, ids, target in self.sets:
            ev = ParticleEvents()
            active, hit = self.active[ps.name], self.hit[ps.name]
            centre = tuple(snap.position(target)) if target is not None else None
            hit_ids: set[int] = set()
            if ps.hit_body:
                hb = snap.handle(snap.body_key(ps.hit_body)).id
                hit_ids = {cp[2] for cp in pb.getContactPoints(bodyA=hb, physicsClientId=c)}
            lost_id = anchor = None
            if ps.lost_body:
                holder = snap.handle(snap.body_key(ps.lost_body))
                lost_id = holder.id
                frame = w.link_frame(holder, holder.links[ps.lost_link])
                anchor = pb.multiplyTransforms(*frame, ps.lost_anchor, (0, 0, 0, 1))[0]
            inside = None
            if ps.outside_of is not None:  # particles still in their container are neither consumed nor lost
                box = ps.outside_of
                holder = w.bodies[box.body]
                inside = (pb.invertTransform(*w.link_frame(holder, holder.links[box.link])), box.radius, box.height)
            for k, pid in enumerate(ids):
                if not active[k]:
                    continue
                pos = base_pose(pid, physicsClientId=c)[0]
                if pid in hit_ids and not hit[k]:
                    hit[k] = True
                    ev.hit += 1
                if inside is not None:
                    (inv_pos, inv_orn), radius, height = inside
                    x, y, z = pb.multiplyTransforms(inv_pos, inv_orn, pos, (0, 0, 0, 1))[0]
                    if x * x + y * y <= radius * radius and -radius <= z <= height:
                        continue
                if centre is not None and math.dist(pos, centre) < ps.consumed_radius:
                    ev.consumed += 1
                    ev.consumed_speed_sum += math.hypot(*base_velocity(pid, physicsClientId=c)[0])
                    active[k] = False
                    self._park(pid, k)
                elif (lost_id is not None and math.dist(pos, anchor) >= ps.lost_distance
                      and not closest(pid, lost_id, ps.lost_distance, physicsClientId=c)):
                    # Within lost_distance of a point inside the holder means certainly near it;
                    # only otherwise is the exact closest-points query needed.
                    ev.lost += 1
                    active[k] = False
                    self._park(pid, k)
            snap.events[ps.name] = ev

    def remaining(self, name: str) -> int:
        return int(self.active[name].sum())

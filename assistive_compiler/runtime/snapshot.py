"""The per-step snapshot of the world that every term reads.

Terms never call pybullet. At bind time every point and joint group a task uses gets a slot;
:meth:`Snapshot.refresh` then reads all of them with one batched ``getLinkStates`` /
``getJointStates`` call per body. Contact queries are made on first use in a step and cached
for the rest of it, so a term that pools several contact pairs costs one query per pair.

Units: metres, m/s, newtons; quaternions (x, y, z, w); world frame unless a method says otherwise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pybullet as pb

from ..references import JointGroup, JointsHandle, NodeSet, NodesHandle, Point, PointHandle, TargetPoint
from ..rotation import quat_conj, quat_matrix, quat_mul, quat_rotate  # noqa: F401  (re-exported)
from ..terms.reads import ContactPoint, ParticleEvents, SceneReads
from .bodies import BodyHandle, own_points
from .world import World

CLOSEST_SLACK_M = (
    0.05  # closest_distance first looks this far beyond its last answer (m); any value gives the same result
)


@dataclass
class _BodyReads:
    links: list[int] = field(default_factory=list)  # link indices (>= 0) read in one getLinkStates
    slots: list[int] = field(default_factory=list)  # slot of each
    base_slots: list[int] = field(default_factory=list)  # slots reading the base (-1)


class Snapshot:
    """Batched reads of the world for one env step, plus the step's action and events: the
    :class:`~assistive_compiler.terms.reads.SceneReads` the terms read."""

    def __init__(self, world: World):
        self.world = world
        self._slots: dict[tuple[str, int], int] = {}
        self._reads: dict[str, _BodyReads] = {}
        self.target_offsets: dict[str, np.ndarray] = {}
        self.target_slots: dict[str, int] = {}  # a surface-drawn target moves between limbs per episode
        self.target_normals: dict[str, np.ndarray] = {}  # outward surface normals (link frame)
        self.target_axes: dict[str, np.ndarray] = {}  # limb axes away from the joint (link frame)
        self.actions: dict[str, np.ndarray] = {"robot": np.zeros(0), "human": np.zeros(0)}
        self.events: dict[str, Any] = {}  # per particle set: ParticleEvents; per marker set: markers cleared (int)
        self._contacts: dict[tuple[int, int], tuple[ContactPoint, ...]] = {}
        self._pooled: dict[
            tuple[tuple[str, ...], tuple[str, ...]], list[ContactPoint]
        ] = {}  # contacts(a, b) this step, per (a, b)
        self._joint_cache: dict[JointsHandle, np.ndarray] = {}
        self.pos, self.orn, self.vel = np.zeros((0, 3)), np.zeros((0, 4)), np.zeros((0, 3))
        self.frames: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self._handles: dict[tuple[str, ...], tuple[BodyHandle, ...]] = {}
        # last closest_distance per (body, bodies): where the next query starts
        self._closest_hint: dict[tuple[str, tuple[str, ...]], float] = {}
        self._garment_nodes: dict[int, np.ndarray] = {}
        # pybullet reports a soft body's contact forces of its last solver sub-step only: scale them
        # back to the physics step (docs/dressing-study.md: then Σ|f_n| ≈ the weight it rests on).
        sub_steps = max(1, world.m.sim.sub_steps)
        self.force_scale: dict[int, float] = {g.soft_id: float(sub_steps) for g in world.garments}

    # -- binding ------------------------------------------------------------------------------
    def body_key(self, name: str) -> str:
        """'person' stands for the active variant; other names are bodies of the manifest."""
        return "person" if name == "person" or name.startswith("person_") else name

    def handle(self, name: str) -> BodyHandle:
        w = self.world
        if name == "person":
            return w.variant_bodies[w.active_variant.name]
        return w.bodies[name]

    def point(self, ref: Point) -> PointHandle:
        """Bind a point reference (a target, or a body's link)."""
        if isinstance(ref, TargetPoint):
            t = self.world.m.targets[ref.target]
            slot = self._slot(t.body, t.link)
            self.target_offsets.setdefault(ref.target, np.asarray(t.offset, dtype=float))
            self.target_slots.setdefault(ref.target, slot)
            return PointHandle(slot, ref.target)
        return PointHandle(self._slot(ref.body, ref.link))

    def place_target(
        self,
        name: str,
        link_name: str,
        offset: Sequence[float] | np.ndarray,
        normal: Sequence[float] | np.ndarray | None = None,
        axis: Sequence[float] | np.ndarray | None = None,
    ) -> None:
        """Put target ``name`` on person link ``link_name`` at ``offset`` (link frame, m) for this
        episode, with an outward surface ``normal`` and the limb ``axis`` (link frame, unit) when
        it lies on a limb's surface."""
        self.target_slots[name] = self._slot("person", link_name)
        self.target_offsets[name] = np.asarray(offset, dtype=float)
        if normal is not None:
            self.target_normals[name] = np.asarray(normal, dtype=float)
        if axis is not None:
            self.target_axes[name] = np.asarray(axis, dtype=float)

    def link_slot(self, body: str, link_name: str) -> int:
        """The slot of a link (read every step from now on)."""
        return self._slot(body, link_name)

    def _slot(self, body: str, link_name: str) -> int:
        key = self.body_key(body)
        link = self.handle(key).links[link_name]
        if (key, link) not in self._slots:
            slot = len(self._slots)
            self._slots[(key, link)] = slot
            reads = self._reads.setdefault(key, _BodyReads())
            if link == -1:
                reads.base_slots.append(slot)
            else:
                reads.links.append(link)
                reads.slots.append(slot)
            # Grow the arrays by one row, keeping what has been read already.
            self.pos = np.vstack([self.pos, np.zeros((1, 3))])
            self.orn = np.vstack([self.orn, [[0.0, 0.0, 0.0, 1.0]]])
            self.vel = np.vstack([self.vel, np.zeros((1, 3))])
        return self._slots[(key, link)]

    def nodes(self, ref: NodeSet) -> NodesHandle:
        """Bind a garment's node set."""
        names = [g.name for g in self.world.garments]
        return NodesHandle(names.index(ref.garment), ref.nodes)

    def node_positions(self, h: NodesHandle) -> np.ndarray:
        """(k, 3) positions of a node set this step, world frame, m (one mesh read per garment per step)."""
        x = self._garment_nodes.get(h.garment)
        if x is None:
            x = self._garment_nodes[h.garment] = self.world.garment_nodes(self.world.garments[h.garment])
        return x[list(h.indices)]

    def joints(self, ref: JointGroup) -> JointsHandle:
        """Bind a joint group (its joints' pybullet indices)."""
        h = self.handle(ref.body)
        return JointsHandle(ref.body, tuple(h.joints[j] for j in ref.joints))

    # -- per step -----------------------------------------------------------------------------
    def refresh(self) -> None:
        """Read every bound link (positions, orientations, velocities) and clear per-step caches."""
        c = self.world.client
        pos, orn, vel = self.pos, self.orn, self.vel
        for key, reads in self._reads.items():
            h = self.handle(key)
            if reads.links:
                states = pb.getLinkStates(
                    h.id, reads.links, computeLinkVelocity=1, computeForwardKinematics=1, physicsClientId=c
                )
                for slot, s in zip(reads.slots, states):
                    pos[slot] = s[4]
                    orn[slot] = s[5]
                    vel[slot] = s[6]
            if reads.base_slots:
                frame_pos, frame_orn = self.world.base_frame(h)
                lin = pb.getBaseVelocity(h.id if h.pose_id is None else h.pose_id, physicsClientId=c)[0]
                for slot in reads.base_slots:
                    pos[slot], orn[slot], vel[slot] = frame_pos, frame_orn, lin
        self._contacts.clear()
        self._pooled.clear()
        self._joint_cache.clear()
        self._garment_nodes.clear()

    def set_frame(self, name: str, pos: Sequence[float], orn: Sequence[float]) -> None:
        """Fix an observation frame for the episode (the robot's and the person's bases do not move)."""
        rot = quat_matrix(orn)
        self.frames[name] = (np.asarray(pos, dtype=float), np.asarray(orn, dtype=float), rot.T)

    # -- what terms read ----------------------------------------------------------------------
    def position(self, h: PointHandle) -> np.ndarray:
        if h.target is None:
            return self.pos[h.slot].copy()
        slot = self.target_slots[h.target]
        return self.pos[slot] + quat_rotate(self.orn[slot], self.target_offsets[h.target])

    def orientation(self, h: PointHandle) -> np.ndarray:
        return self.orn[h.slot if h.target is None else self.target_slots[h.target]].copy()

    def velocity(self, h: PointHandle) -> np.ndarray:
        return self.vel[h.slot if h.target is None else self.target_slots[h.target]].copy()

    def normal(self, h: PointHandle) -> np.ndarray:
        """Outward surface normal at a surface-drawn target, world frame (zero for other points)."""
        if h.target is None or h.target not in self.target_normals:
            return np.zeros(3)
        return quat_rotate(self.orn[self.target_slots[h.target]], self.target_normals[h.target])

    def axis(self, h: PointHandle) -> np.ndarray:
        """Limb axis (away from its joint) at a surface-drawn target, world frame (zero for other points)."""
        if h.target is None or h.target not in self.target_axes:
            return np.zeros(3)
        return quat_rotate(self.orn[self.target_slots[h.target]], self.target_axes[h.target])

    def joint_angles(self, h: JointsHandle) -> np.ndarray:
        q = self._joint_cache.get(h)
        if q is None:
            states = pb.getJointStates(self.handle(h.body).id, h.indices, physicsClientId=self.world.client)
            q = self._joint_cache[h] = np.array([s[0] for s in states])
        return q.copy()

    def point_in_frame(self, frame: str, p: np.ndarray) -> np.ndarray:
        if frame == "world":
            return p
        fpos, _, world_to_frame = self.frames[frame]
        return world_to_frame @ (p - fpos)

    def vector_in_frame(self, frame: str, v: np.ndarray) -> np.ndarray:
        if frame == "world":
            return v
        return self.frames[frame][2] @ v

    def quat_in_frame(self, frame: str, q: np.ndarray) -> np.ndarray:
        if frame == "world":
            return q
        return quat_mul(quat_conj(self.frames[frame][1]), q)

    def action(self, agent: str) -> np.ndarray:
        if agent == "all":
            return np.concatenate([self.actions["robot"], self.actions["human"]])
        return self.actions[agent]

    def particle_events(self, name: str) -> ParticleEvents:
        events: ParticleEvents = self.events[name]
        return events

    def markers_cleared(self, name: str) -> int:
        return int(self.events[name])

    def _contact_points(self, a: int, b: int) -> tuple[ContactPoint, ...]:
        key = (a, b)
        if key not in self._contacts:
            self._contacts[key] = pb.getContactPoints(bodyA=a, bodyB=b, physicsClientId=self.world.client)
        return self._contacts[key]

    def body_handles(self, names: Sequence[str]) -> tuple[BodyHandle, ...]:
        """Handles of named bodies ('person' = the active variant), cached for the episode."""
        key = tuple(names)
        handles = self._handles.get(key)
        if handles is None:
            handles = self._handles[key] = tuple(self.handle(self.body_key(n)) for n in names)
        return handles

    def begin_episode(self) -> None:
        """Forget what depended on the last episode's person variant."""
        self._handles.clear()
        self._pooled.clear()
        self._closest_hint.clear()

    def contacts(self, a: Sequence[str], b: Sequence[str]) -> list[ContactPoint]:
        """pybullet contact points between any body of ``a`` (as bodyA) and any of ``b`` this step
        (a list shared by the step's callers: do not modify it)."""
        key = (tuple(a), tuple(b))
        out = self._pooled.get(key)
        if out is None:
            out = []
            for ha in self.body_handles(a):
                for hb in self.body_handles(b):
                    out.extend(own_points(self._contact_points(ha.id, hb.id), ha, hb))
            self._pooled[key] = out
        return out

    def closest_distance(self, a: str, b: Sequence[str], max_distance: float) -> float:
        """Smallest surface distance between body ``a`` and any body of ``b`` within ``max_distance`` (m).

        Asked first within the last answer for the same bodies plus ``CLOSEST_SLACK_M`` (most link
        pairs then drop out in the broadphase instead of each returning its closest points), and
        within ``max_distance`` only when nothing that near is found: the same minimum, since every
        pair nearer than the first query's reach is reported by it."""
        ha = self.body_handles([a])[0]
        hbs = self.body_handles(b)
        key = (a, tuple(b))
        hint = self._closest_hint.get(key)
        if hint is not None and hint + CLOSEST_SLACK_M < max_distance:
            reach = hint + CLOSEST_SLACK_M
            best = self._closest(ha, hbs, reach)
            if best is not None and best <= reach:
                self._closest_hint[key] = best
                return best
        best = self._closest(ha, hbs, max_distance)
        best = max_distance if best is None else min(best, max_distance)
        self._closest_hint[key] = best
        return best

    def _closest(self, ha: BodyHandle, hbs: tuple[BodyHandle, ...], reach: float) -> float | None:
        """Smallest distance (m) of the closest points of body ``ha`` and bodies ``hbs`` within ``reach``; None if none."""
        client, best = self.world.client, None
        for hb in hbs:
            points = own_points(pb.getClosestPoints(ha.id, hb.id, reach, physicsClientId=client), ha, hb)
            if points:
                d = min([cp[8] for cp in points])
                best = d if best is None or d < best else best
        return best

    def contact_force(
        self, a: Sequence[str], b: Sequence[str], near: PointHandle | None = None, radius: float = 0.0
    ) -> float:
        """Σ normal force (N) of contacts between any body of ``a`` and any of ``b``; with ``near``,
        only contacts whose point on ``a`` lies within ``radius`` of that point."""
        total = 0.0
        centre = self.position(near).tolist() if near is not None else None
        scale = self.force_scale
        for cp in self.contacts(a, b):
            if centre is None or math.dist(cp[5], centre) <= radius:
                total += cp[9] * (scale.get(cp[1]) or scale.get(cp[2]) or 1.0)
        return total

    def contact_force_and_count(self, a: str, b: Sequence[str], distance: float) -> tuple[float, int]:
        """Contact force of body ``a`` on ``b`` (N) and the number of closest points within ``distance``."""
        ha = self.body_handles([a])[0]
        count = sum(
            len(own_points(pb.getClosestPoints(ha.id, hb.id, distance, physicsClientId=self.world.client), ha, hb))
            for hb in self.body_handles(b)
        )
        return self.contact_force([a], b), count


if TYPE_CHECKING:  # mypy checks that the snapshot offers every read the terms make
    _SNAPSHOT_READS: type[SceneReads] = Snapshot

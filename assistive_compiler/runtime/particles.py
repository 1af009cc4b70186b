"""Particle lifecycles (food, water): active → consumed (reached the target) | lost (left its
container); the first contact of an active particle with ``hit_body`` counts once as a hit.

Removed particles are parked far away (``PARK``, 50 m up), apart from each other, at rest and
without gravity compensation, so they touch nothing; they come back at reset. A parked particle
falls under the world's gravity, so it is put back at its parking spot at rest before it could
fall 49 m: every :attr:`ParticleSystem.repark_steps` env steps after it was parked (a function
of the episode's history only, so seeded episodes replay exactly). Under the old infinite ground
plane, 64 of them landing made a Drinking env step with the water carried a sixth slower; the
floor slab does not reach the parking area, and reparking keeps their positions bounded. Nothing
else about them changes: a mass of 0 would make them static objects for good, changing collision
filters re-inserts them in the broadphase, which reorders contact pairs, and Bullet's sleeping
does not restore a multibody's velocity when it wakes — each would make an episode depend on the
ones before it or change the physics. Events are evaluated once per env step, as in the reference.

**Resting in a container** (a set's ``rest``, optional): particles at rest in their container
are *carried*: their positions in the container frame are kept and the bodies themselves are
parked like removed ones, so the physics solves none of their contacts. The test uses the
container's apparent "up" −(g − a), a its acceleration over the last env step, written in the
container's frame. After an env step the free particles come to rest when the container's
effective tilt (its +z against that up) is at most ``rest.max_tilt``, every active particle is
inside it and their mean speed relative to it has stayed at most ``rest.max_speed`` for
``rest.still_steps`` env steps in a row; they are then carried, and the up of that moment is
remembered. A mean, not the fastest particle: under solver sub-steps a resting heap always has a
particle or two rattling at several cm/s, while the heap itself creeps at millimetres per second
(docs/physics.md). At the start of an env step carried particles are put back at their carried
positions with the container's velocity (linear plus ω × r) and simulated when the last env
step's up has turned more than ``rest.max_turn`` from the remembered one, its effective tilt
exceeds ``rest.max_tilt``, or the container ended it within ``rest.near_distance`` of
``rest.near_body`` (there nothing rests: what the particles do near that body, touch it or be
consumed, happens in the physics, as without the shortcut): a heap that came to rest tilted stays carried while the cup is held
at that tilt, and only a turn of the apparent gravity makes it flow. A reset carries them at
their settled start positions (settled at compile time, so at rest) when the container starts
within ``max_tilt``, unless ``rest.carry_at_reset`` is off: then they are simulated until they
rest (the spoon's food settles as a stack that the first tilt topples). While carried, their weight pushes on the container
(:meth:`World.set_load`), as it would through their contacts. Carried particles are active and
inside their container, so they produce no events; renders draw them where they are carried
(:meth:`ParticleSystem.visual_spheres`). Every decision is a function of the world's state, so
seeded episodes stay reproducible.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb

from ..artifact import Container, ParticleSet
from ..references import PointHandle, TargetPoint
from ..rotation import quat_matrix, vec_angle
from ..terms.reads import ParticleEvents
from .bodies import PARK, own_points
from .component import EnvStep, Episode, EpisodeComponent
from .snapshot import Snapshot
from .world import World

_AXIS = np.array([0.0, 0.0, 1.0])  # a container's axis in its frame, towards its opening


class ParticleSystem(EpisodeComponent):
    """All particle sets of a world."""

    def __init__(self, world: World, snap: Snapshot):
        self.world = world
        self.snap = snap
        self.sets: list[tuple[ParticleSet, list[int], PointHandle | None]] = []
        for ps in world.m.particles:
            target = snap.point(TargetPoint(target=ps.consumed_target)) if ps.consumed_target else None
            self.sets.append((ps, world.particles[ps.name], target))
        self.active: dict[str, np.ndarray] = {}
        self.hit: dict[str, np.ndarray] = {}
        #: Per set with ``rest``: which particles are carried by their container now, and where (container frame, m).
        self.carried: dict[str, np.ndarray] = {}
        self.carried_at: dict[str, np.ndarray] = {}
        self._container_velocity: dict[str, np.ndarray] = {}  # at the end of the last env step, world frame, m/s
        #: Per set with ``rest``: the apparent up (unit, container frame) at the end of the last env
        #: step, and when the carried particles came to rest; env steps in a row the free ones were still.
        self._last_up: dict[str, np.ndarray] = {}
        self._rest_up: dict[str, np.ndarray] = {}
        self._still_steps: dict[str, int] = {}
        #: Per set with ``rest.near_body``: whether its container was within ``near_distance`` of
        #: that body at the end of the last env step (its particles are then simulated).
        self._near: dict[str, bool] = {}
        self._dt = world.m.sim.time_step * world.m.sim.frame_skip
        self._gravity = np.array([0.0, 0.0, world.m.sim.gravity])
        #: Env steps a parked particle may fall before it is put back at its parking spot: the free
        #: fall from PARK's height to 1 m above the ground (linear damping only slows it); None
        #: when the world has no downward gravity.
        g = -world.world_gravity
        self.repark_steps = max(1, int(math.sqrt(2.0 * (PARK[2] - 1.0) / g) / self._dt)) if g > 0 else None
        self._parked_age: dict[
            int, tuple[int, int]
        ] = {}  # parked particle id → (env steps since parked, index k in its set)

    # -- containers ------------------------------------------------------------------------------
    def _container_state(self, box: Container):
        """World pose of a container's frame (position, rotation matrix) and the rigid velocity
        field of its body: (origin of that field, linear velocity there, angular velocity)."""
        w, c = self.world, self.world.client
        holder = w.bodies[box.body]
        link = holder.links[box.link]
        if link == -1:
            pos, orn = w.base_frame(holder)
            com = pb.getBasePositionAndOrientation(holder.id, physicsClientId=c)[0]
            lin, ang = pb.getBaseVelocity(holder.id, physicsClientId=c)
        else:  # one query: the link's URDF frame (what link_frame reads), its centre of mass and velocities
            s = pb.getLinkState(holder.id, link, computeLinkVelocity=1, computeForwardKinematics=1, physicsClientId=c)
            pos, orn, com, lin, ang = s[4], s[5], s[0], s[6], s[7]
        return np.asarray(pos), quat_matrix(orn), np.asarray(com), np.asarray(lin), np.asarray(ang)

    def _apparent_up(self, name: str, rot: np.ndarray, lin: np.ndarray) -> np.ndarray:
        """The apparent up −(g − a) of a container, a its acceleration over the last env step, as a
        unit vector in its frame (+z: the container's axis, towards its opening)."""
        prev = self._container_velocity.get(name)
        accel = np.zeros(3) if prev is None else (lin - prev) / self._dt
        up = accel - self._gravity
        norm = float(np.linalg.norm(up))
        return np.array([0.0, 0.0, -1.0]) if norm < 1e-9 else rot.T @ (up / norm)

    @staticmethod
    def _inside(box: Container, local: np.ndarray) -> np.ndarray:
        """Which container-frame points (n, 3) lie in the container's cylinder."""
        r2 = local[:, 0] ** 2 + local[:, 1] ** 2
        return (r2 <= box.radius**2) & (local[:, 2] >= -box.radius) & (local[:, 2] <= box.height)

    def _positions(self, ids: list[int]) -> np.ndarray:
        c, pose = self.world.client, pb.getBasePositionAndOrientation
        return np.array([pose(pid, c)[0] for pid in ids], dtype=float).reshape(
            -1, 3
        )  # positional: pybullet parses keywords slowly

    def _carry(self, ps: ParticleSet, ids: list[int], which: np.ndarray, local: np.ndarray) -> None:
        """Park the particles ``which`` (bool mask) and remember their container-frame positions."""
        carried, at = self.carried[ps.name], self.carried_at[ps.name]
        for k in np.flatnonzero(which):
            at[k] = local[k]
            carried[k] = True
            self._park(ids[k], int(k))
        self._carry_weight(ps)

    def _carry_weight(self, ps: ParticleSet) -> None:
        """The carried particles' weight (their gravity, N) pushes on the container's link, as it would
        through their contacts if they were simulated (0 when none are carried)."""
        w, box = self.world, ps.rest.container
        holder = w.bodies[box.body]
        w.set_load(holder.id, holder.links[box.link], float(self.carried[ps.name].sum()) * ps.mass * w.m.sim.gravity)

    def _release(self, ps: ParticleSet, ids: list[int]) -> None:
        """Put the carried particles back where they were carried, moving with the container."""
        c = self.world.client
        pos, rot, com, lin, ang = self._container_state(ps.rest.container)
        carried, at = self.carried[ps.name], self.carried_at[ps.name]
        for k in np.flatnonzero(carried):
            p = pos + rot @ at[k]
            v = lin + np.cross(ang, p - com)
            self._unpark(ids[k])
            pb.resetBasePositionAndOrientation(ids[k], p.tolist(), (0, 0, 0, 1), physicsClientId=c)
            pb.resetBaseVelocity(ids[k], v.tolist(), (0, 0, 0), physicsClientId=c)
        carried[:] = False
        self._still_steps[ps.name] = 0
        self._carry_weight(ps)

    # -- lifecycle -------------------------------------------------------------------------------
    def reset(self, episode: Episode) -> None:
        """Place every particle at its settled position in its holder's frame; all active (and
        carried, for a set that rests in a container that starts within its tilt limit and is
        carried from the reset on)."""
        w, c = self.world, self.world.client
        for ps, ids, _ in self.sets:
            holder = w.bodies[ps.attach]
            frame_pos, frame_orn = w.link_frame(holder, holder.links[ps.attach_link])
            for pid, local in zip(ids, ps.start_positions):
                self._unpark(pid)
                pos, _ = pb.multiplyTransforms(frame_pos, frame_orn, local, (0, 0, 0, 1))
                pb.resetBasePositionAndOrientation(pid, pos, (0, 0, 0, 1), physicsClientId=c)
                pb.resetBaseVelocity(pid, (0, 0, 0), (0, 0, 0), physicsClientId=c)
            self.active[ps.name] = np.ones(ps.count, dtype=bool)
            self.hit[ps.name] = np.zeros(ps.count, dtype=bool)
            self.snap.events[ps.name] = ParticleEvents()
            if ps.rest is not None:
                self.carried[ps.name] = np.zeros(ps.count, dtype=bool)
                self.carried_at[ps.name] = np.zeros((ps.count, 3))
                self._carry_weight(ps)
                self._container_velocity.pop(ps.name, None)
                self._still_steps[ps.name] = 0
                self._maybe_carry(ps, ids, settled=True)

    def before_physics(self, step: EnvStep) -> None:
        """At the start of an env step: simulate carried particles again if the last env step turned
        their container's apparent up too far from where they came to rest, or tilted it too far."""
        for ps, ids, _ in self.sets:
            if ps.rest is None or not self.carried[ps.name].any():
                continue
            up = self._last_up[ps.name]
            if (
                vec_angle(up, self._rest_up[ps.name]) > ps.rest.max_turn
                or vec_angle(up, _AXIS) > ps.rest.max_tilt
                or self._near.get(ps.name, False)
            ):
                self._release(ps, ids)

    def _container_near(self, ps: ParticleSet) -> bool:
        """Whether the set's container link is within ``rest.near_distance`` (m) of ``rest.near_body``."""
        rest = ps.rest
        if rest.near_body is None:
            return False
        w = self.world
        holder, near = w.bodies[rest.container.body], self.snap.handle(self.snap.body_key(rest.near_body))
        return bool(
            pb.getClosestPoints(
                holder.id, near.id, rest.near_distance, holder.links[rest.container.link], physicsClientId=w.client
            )
        )

    def _maybe_carry(self, ps: ParticleSet, ids: list[int], settled: bool = False) -> None:
        """After an env step: carry the set's free particles if they have rested in their container
        (see the module's docstring); ``settled``: at a reset, at their settled start positions."""
        box, name = ps.rest.container, ps.name
        pos, rot, com, lin, ang = self._container_state(box)
        up = self._last_up[name] = self._apparent_up(name, rot, lin)
        self._container_velocity[name] = lin
        near = self._near[name] = self._container_near(ps)
        free = self.active[name] & ~self.carried[name]
        if not free.any() or (settled and not ps.rest.carry_at_reset):
            return
        if near or vec_angle(up, _AXIS) > ps.rest.max_tilt:
            self._still_steps[name] = 0
            return
        idx = np.flatnonzero(free)
        world = self._positions([ids[k] for k in idx])
        local = (world - pos) @ rot  # rotᵀ (p − pos), row-wise
        if not settled:
            if not self._still(ps, ids, idx, world, local, com, lin, ang):
                self._still_steps[name] = 0
                return
            self._still_steps[name] += 1
            if self._still_steps[name] < ps.rest.still_steps:
                return
        full = np.zeros((ps.count, 3))
        full[idx] = local
        self._carry(ps, ids, free, full)
        self._rest_up[name] = up
        self._still_steps[name] = 0

    def _still(
        self,
        ps: ParticleSet,
        ids: list[int],
        idx: np.ndarray,
        world: np.ndarray,
        local: np.ndarray,
        com: np.ndarray,
        lin: np.ndarray,
        ang: np.ndarray,
    ) -> bool:
        """Whether the free particles ``idx`` (world and container-frame positions, m) are still in
        their container this env step: all inside it, and their mean speed relative to it (m/s) at
        most ``rest.max_speed``."""
        if not self._inside(ps.rest.container, local).all():
            return False
        c = self.world.client
        vel = np.array([pb.getBaseVelocity(ids[k], physicsClientId=c)[0] for k in idx], dtype=float)
        relative = vel - (lin + np.cross(ang, world - com))
        return float(np.mean(np.linalg.norm(relative, axis=1))) <= ps.rest.max_speed

    def _park(self, pid: int, k: int) -> None:
        """Put particle ``pid`` (index ``k`` in its set) at its parking spot, at rest."""
        c = self.world.client
        pb.resetBasePositionAndOrientation(
            pid, (PARK[0] - 5.0 - 0.1 * k, PARK[1], PARK[2]), (0, 0, 0, 1), physicsClientId=c
        )
        pb.resetBaseVelocity(pid, (0, 0, 0), (0, 0, 0), physicsClientId=c)
        self.world.parked.add(pid)
        self._parked_age[pid] = (0, k)

    def _unpark(self, pid: int) -> None:
        """Particle ``pid`` is back in the scene (the caller places it)."""
        self.world.parked.discard(pid)
        self._parked_age.pop(pid, None)

    def _age_parked(self) -> None:
        """Once per env step: parked particles that have fallen for ``repark_steps`` go back up."""
        if self.repark_steps is None:
            return
        for pid, (age, k) in list(self._parked_age.items()):
            if age + 1 >= self.repark_steps:
                self._park(pid, k)
            else:
                self._parked_age[pid] = (age + 1, k)

    def after_step(self) -> None:
        """Evaluate this step's events (after physics, after the snapshot refresh)."""
        w, c, snap = self.world, self.world.client, self.snap
        base_velocity, closest = pb.getBaseVelocity, pb.getClosestPoints
        self._age_parked()
        for ps, ids, target in self.sets:
            ev = ParticleEvents()
            active, hit = self.active[ps.name], self.hit[ps.name]
            carried = self.carried.get(ps.name)
            live = active & ~carried if carried is not None else active.copy()
            idx = np.flatnonzero(live)
            if not len(idx):
                snap.events[ps.name] = ev
                if ps.rest is not None:
                    self._maybe_carry(ps, ids)
                continue
            positions = self._positions([ids[k] for k in idx])
            centre = snap.position(target) if target is not None else None
            hit_ids: set[int] = set()
            if ps.hit_body:
                hb = snap.handle(snap.body_key(ps.hit_body))
                hit_ids = {cp[2] for cp in own_points(pb.getContactPoints(bodyA=hb.id, physicsClientId=c), hb)}
            lost_to = anchor = None
            if ps.lost_body:
                holder = lost_to = snap.handle(snap.body_key(ps.lost_body))
                frame = w.link_frame(holder, holder.links[ps.lost_link])
                anchor = np.asarray(pb.multiplyTransforms(*frame, ps.lost_anchor, (0, 0, 0, 1))[0])
            inside = np.zeros(len(idx), dtype=bool)
            if ps.outside_of is not None:  # particles still in their container are neither consumed nor lost
                box = ps.outside_of
                holder = w.bodies[box.body]
                fpos, forn = w.link_frame(holder, holder.links[box.link])
                inside = self._inside(box, (positions - np.asarray(fpos)) @ quat_matrix(forn))
            to_centre = np.linalg.norm(positions - centre, axis=1) if centre is not None else None
            to_anchor = np.linalg.norm(positions - anchor, axis=1) if anchor is not None else None
            for j, k in enumerate(idx):
                pid = ids[k]
                if pid in hit_ids and not hit[k]:
                    hit[k] = True
                    ev.hit += 1
                if inside[j]:
                    continue
                if to_centre is not None and to_centre[j] < ps.consumed_radius:
                    ev.consumed += 1
                    ev.consumed_speed_sum += math.hypot(*base_velocity(pid, physicsClientId=c)[0])
                    active[k] = False
                    self._park(pid, int(k))
                elif (
                    lost_to is not None
                    and to_anchor[j] >= ps.lost_distance
                    and not own_points(closest(lost_to.id, pid, ps.lost_distance, physicsClientId=c), lost_to)
                ):
                    # Within lost_distance of a point inside the holder means certainly near it;
                    # only otherwise is the exact closest-points query needed.
                    ev.lost += 1
                    active[k] = False
                    self._park(pid, int(k))
            snap.events[ps.name] = ev
            if ps.rest is not None:
                self._maybe_carry(ps, ids)

    def shown_positions(self, name: str) -> np.ndarray:
        """Where each particle of set ``name`` appears, (n, 3) world m: a carried one where its
        container carries it, any other where its body is (removed ones: parked far away)."""
        ps, ids, _ = next(s for s in self.sets if s[0].name == name)
        out = self._positions(ids)
        carried = self.carried[name] & self.active[name] if name in self.carried else np.zeros(len(ids), dtype=bool)
        if carried.any():
            pos, rot = self._container_state(ps.rest.container)[:2]
            out[carried] = pos + self.carried_at[name][carried] @ rot.T
        return out

    def visual_spheres(self) -> list[tuple[list[float], float, tuple]]:
        """(position, radius m, rgba) of each carried particle, for renders to draw where it is
        carried (its body is parked: see above). Reads the world, changes nothing."""
        out = []
        for ps, _, _ in self.sets:
            if ps.rest is None:
                continue
            carried = self.carried[ps.name] & self.active[ps.name]
            if not carried.any():
                continue
            shown = self.shown_positions(ps.name)
            out += [(shown[k].tolist(), ps.radius, tuple(ps.colors[k])) for k in np.flatnonzero(carried)]
        return out

    def remaining(self, name: str) -> int:
        return int(self.active[name].sum())

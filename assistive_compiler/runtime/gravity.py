"""Per-body gravity on stock pybullet (what the reference's fork did per body): the world gravity
is set to the value that needs the fewest compensated links, and every movable link of a body with
a different gravity gets an external force m·(g_body − g_world) at its centre of mass before each
physics step (forces are cleared by ``stepSimulation``). The effect on those links is exactly the
body's own gravity. Other loads (N, world z) ride along with the same forces (:meth:`set_load`).
"""

from __future__ import annotations

import pybullet as pb

from ..artifact import Manifest
from .bodies import BodyHandle


class PerBodyGravity:
    """The gravity part of :class:`~.world.World`: choosing the world gravity, and the compensating
    forces applied before every physics step."""

    client: int
    m: Manifest
    bodies: dict[str, BodyHandle]
    particles: dict[str, list[int]]

    def _set_gravity(self) -> None:
        """Choose the world gravity needing the fewest compensated links; list those links."""
        c = self.client
        candidates: dict[float, list[tuple[int, int, float]]] = {}
        welded = {att.body for att in self.m.tools if att.welded}  # they feel the robot's gravity (the compiler checks)
        declared = {
            b.name: (self.m.sim.gravity if b.gravity is None else b.gravity)
            for b in self.m.bodies
            if b.name not in welded
        }
        for ps in self.m.particles:
            for k in range(len(self.particles[ps.name])):
                declared[f"{ps.name}#{k}"] = self.m.sim.gravity
        options = sorted(set(declared.values()) | ({self.m.sim.gravity} if self.m.garments else set()))
        for g_world in options:
            comp: list[tuple[int, int, float]] = []
            for name, g in declared.items():
                if g == g_world:
                    continue
                bid = self._body_id(name)
                for link, mass in self._moving_links(bid):
                    comp.append((bid, link, mass * (g - g_world)))
            candidates[g_world] = comp
        # A soft body feels only the world gravity: with a garment that is the spec's sim gravity.
        self.world_gravity = (
            self.m.sim.gravity if self.m.garments else min(options, key=lambda g: (len(candidates[g]), -abs(g)))
        )
        groups: dict[int, tuple[list[int], list[float]]] = {}
        for bid, link, fz in candidates[self.world_gravity]:
            links, forces = groups.setdefault(bid, ([], []))
            links.append(link)
            forces.append(fz)
        #: Per body: (id, links, z-forces) applied before every physics step; ids in ``parked`` are skipped.
        self.gravity_groups = [(bid, links, forces) for bid, (links, forces) in groups.items()]
        self._gravity_plan = (
            None  # gravity_groups and loads rearranged for the per-step loop (see _apply_gravity_compensation)
        )
        #: (body id, link) → a z-force (N, world frame) applied at the link's centre of mass with the gravity compensation.
        self.loads: dict[tuple[int, int], float] = {}
        self.parked: set[int] = set()
        pb.setGravity(0, 0, self.world_gravity, physicsClientId=c)

    def _body_id(self, name: str) -> int:
        if "#" in name:
            set_name, k = name.split("#")
            return self.particles[set_name][int(k)]
        return self.bodies[name].id

    def _moving_links(self, bid: int) -> list[tuple[int, float]]:
        """(link index, mass) of every link that can move (fixed-base chains of fixed joints can't)."""
        c = self.client
        fixed_base = pb.getDynamicsInfo(bid, -1, physicsClientId=c)[0] == 0 or self._is_fixed_base(bid)
        out = [] if fixed_base else [(-1, pb.getDynamicsInfo(bid, -1, physicsClientId=c)[0])]
        moves = {-1: not fixed_base}
        for j in range(pb.getNumJoints(bid, physicsClientId=c)):
            info = pb.getJointInfo(bid, j, physicsClientId=c)
            moves[j] = moves[info[16]] or info[2] != pb.JOINT_FIXED
            if moves[j]:
                out.append((j, pb.getDynamicsInfo(bid, j, physicsClientId=c)[0]))
        return out

    def _is_fixed_base(self, bid: int) -> bool:
        for b in self.m.bodies:
            if self.bodies[b.name].id == bid and self.bodies[b.name].base_link == -1:
                return b.fixed_base
        return False

    def set_load(self, bid: int, link: int, fz: float) -> None:
        """Push link ``link`` of body ``bid`` with ``fz`` (N, world z, at its centre of mass) before every
        physics step until changed; 0 removes it. E.g. the weight of particles a container carries
        outside the physics (:mod:`.particles`)."""
        if fz:
            self.loads[(bid, link)] = fz
        else:
            self.loads.pop((bid, link), None)
        self._gravity_plan = None

    def _apply_gravity_compensation(self) -> None:
        c = self.client
        apply, world = pb.applyExternalForce, pb.WORLD_FRAME
        base_pose, link_states = pb.getBasePositionAndOrientation, pb.getLinkStates
        parked = self.parked
        plan = self._gravity_plan
        if (
            plan is None or plan[0] is not self.gravity_groups
        ):  # per body: base force, child links, their forces (built on change)
            per_body: dict[int, dict[int, float]] = {}
            for (bid, link), fz in [
                ((bid, index), f) for bid, links, forces in self.gravity_groups for index, f in zip(links, forces)
            ] + list(self.loads.items()):
                on_body = per_body.setdefault(bid, {})
                on_body[link] = on_body.get(link, 0.0) + fz
            plan = self._gravity_plan = (
                self.gravity_groups,
                [
                    (
                        bid,
                        (0.0, 0.0, f[-1]) if -1 in f else None,
                        [index for index in f if index >= 0],
                        [(0.0, 0.0, f[index]) for index in f if index >= 0],
                    )
                    for bid, f in per_body.items()
                ],
            )
        # Positional arguments: pybullet parses keywords slowly (0.5 µs per force here, up to 90 per env step).
        for bid, base_force, children, child_forces in plan[1]:
            if bid in parked:
                continue
            if base_force is not None:
                apply(bid, -1, base_force, base_pose(bid, c)[0], world, c)
            if children:
                for link, force, state in zip(children, child_forces, link_states(bid, children, physicsClientId=c)):
                    apply(bid, link, force, state[0], world, c)

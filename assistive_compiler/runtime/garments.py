"""Garments (cloth) in the world: each a mass-spring soft body whose held nodes are pinned to a
massless, collision-free anchor body. :meth:`HeldGarments.follow_grips` teleports the anchors to
the hand's held frame after every physics step and :meth:`HeldGarments.reset_garments` puts the
settled nodes back at reset (``restoreState`` does not cover soft-body nodes). The garment's body
handle has the soft body's id and the anchor's pose. World frame, m.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet as pb

from ..artifact import Manifest
from ..rotation import quat_matrix
from .bodies import PARK, BodyHandle, GarmentHandle


class HeldGarments:
    """The garment part of :class:`~.world.World`: loading the garments, and keeping each at the
    robot's held frame (through the World's ``link_frame``)."""

    client: int
    m: Manifest
    dir: Path
    ground: int
    bodies: dict[str, BodyHandle]
    robot: BodyHandle
    garments: list[GarmentHandle]

    def _create_garments(self) -> None:
        """Load each garment as a soft body with its held nodes pinned to an anchor body (see
        :func:`assistive_compiler.garment.load_garment`); it waits parked until :meth:`reset_garments`.
        The garment's body handle has the soft body's id (contacts) and the anchor's pose (its
        ``held`` point)."""
        from ..garment import load_garment, read_obj_faces

        c = self.client
        self.garments: list[GarmentHandle] = []
        for k, g in enumerate(self.m.garments):
            park = (PARK[0] + 20.0 + 5.0 * k, PARK[1], PARK[2])
            sb, anchor = load_garment(
                pb,
                c,
                self.dir / g.obj,
                park,
                (0, 0, 0, 1),
                g.mass,
                g.collision_margin,
                g.elastic_stiffness,
                g.damping_stiffness,
                g.bending_stiffness,
                g.friction,
                g.anchored,
                rgba=g.rgba,
            )
            self.garments.append(
                GarmentHandle(
                    g.name,
                    sb,
                    anchor,
                    self.robot.links[g.parent_link],
                    (g.grip_position, g.grip_orientation),
                    np.asarray(g.nodes_in_held, dtype=float),
                    read_obj_faces(self.dir / g.obj),
                    tuple(g.rgba),
                )
            )
            self.bodies[g.name] = BodyHandle(
                g.name, sb, {"held": -1}, {}, ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)), pose_id=anchor
            )
            if g.collides_with is not None:  # contact with every other body (and the floor) off
                keep = {
                    b.name
                    for b in self.m.bodies
                    if (b.kind == "person" and "person" in g.collides_with) or b.name in g.collides_with
                }
                others = [self.ground] + [
                    h.id for name, h in self.bodies.items() if name not in keep and name != g.name
                ]
                for bid in others:
                    for link in range(-1, pb.getNumJoints(bid, physicsClientId=c)):
                        pb.setCollisionFilterPair(sb, bid, -1, link, 0, physicsClientId=c)

    def held_pose(self, g: GarmentHandle):
        """World pose of a garment's held frame: its robot link's URDF frame times the grip."""
        pos, orn = self.link_frame(self.robot, g.link)
        return pb.multiplyTransforms(pos, orn, *g.grip)

    def follow_grips(self) -> None:
        """Teleport every garment's anchor to its held frame (the pinned nodes follow in the next step)."""
        c = self.client
        for g in self.garments:
            pos, orn = self.held_pose(g)
            pb.resetBasePositionAndOrientation(g.anchor_id, pos, orn, physicsClientId=c)

    def reset_garments(self) -> None:
        """Every garment back to its settled shape at its held frame, at rest (call after the robot
        is placed). ``restoreState`` does not cover soft-body nodes: ``resetMeshData`` sets them and
        ``resetBaseVelocity`` zeroes their velocities (well under a millisecond)."""
        c = self.client
        for g in self.garments:
            pos, orn = self.held_pose(g)
            pb.resetBasePositionAndOrientation(g.anchor_id, pos, orn, physicsClientId=c)
            rot = quat_matrix(orn)
            world = g.nodes_in_held @ rot.T + np.asarray(pos)
            pb.resetMeshData(g.soft_id, vertices=world.tolist(), physicsClientId=c)
            pb.resetBaseVelocity(g.soft_id, (0, 0, 0), (0, 0, 0), physicsClientId=c)

    def garment_nodes(self, g: GarmentHandle) -> np.ndarray:
        """(n, 3) node positions of a garment, world frame, m."""
        return np.asarray(
            pb.getMeshData(g.soft_id, -1, flags=pb.MESH_DATA_SIMULATION_MESH, physicsClientId=self.client)[1],
            dtype=float,
        )

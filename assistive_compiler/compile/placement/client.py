"""The private pybullet DIRECT client the compiler places bodies in (never shared with a runtime).

:class:`PlacementClient` takes the task's contact breaking threshold (m) and gives the few
queries placement needs on top of raw pybullet (``.p`` with ``.client``): load a URDF, a link's
index by name, a link's URDF-frame world pose, a body's joint indices by name, place a body by
its URDF base frame (not its centre of mass), contact tests and per-body friction. Positions in
m, orientations as quaternions (x, y, z, w), all in the world frame."""

from __future__ import annotations

from pathlib import Path

from ...bullet import connect


class PlacementClient:
    """A private pybullet world used only at compile time."""

    def __init__(self, contact_breaking_threshold: float) -> None:
        import pybullet

        self.p = pybullet
        self.client = connect(contact_breaking_threshold)

    def close(self) -> None:
        self.p.disconnect(self.client)

    def load(self, path: Path, pos, orn, fixed: bool) -> int:
        return self.p.loadURDF(str(path), pos, orn, useFixedBase=fixed, physicsClientId=self.client)

    def link_index(self, body: int, name: str) -> int:
        """Index of link ``name`` of ``body`` (-1 for the base)."""
        p, c = self.p, self.client
        if p.getBodyInfo(body, physicsClientId=c)[0].decode() == name:
            return -1
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            if p.getJointInfo(body, j, physicsClientId=c)[12].decode() == name:
                return j
        raise KeyError(name)

    def link_pose(self, body: int, link: int):
        """World pose of a link's URDF frame (the base's too, not its centre of mass)."""
        p, c = self.p, self.client
        if link == -1:
            com_pos, com_orn = p.getBasePositionAndOrientation(body, physicsClientId=c)
            inertial_pos, inertial_orn = p.getDynamicsInfo(body, -1, physicsClientId=c)[3:5]
            inv_pos, inv_orn = p.invertTransform(inertial_pos, inertial_orn)
            return p.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)
        s = p.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=c)
        return s[4], s[5]

    def named_link_pose(self, body: int, name: str):
        """World pose of link ``name``'s URDF frame."""
        return self.link_pose(body, self.link_index(body, name))

    def joint_index(self, body: int) -> dict[str, int]:
        p, c = self.p, self.client
        return {
            p.getJointInfo(body, j, physicsClientId=c)[1].decode(): j
            for j in range(p.getNumJoints(body, physicsClientId=c))
        }

    def place(self, body: int, pos, orn) -> None:
        """Put a body's URDF base frame (not its centre of mass) at (pos, orn)."""
        p, c = self.p, self.client
        inertial_pos, inertial_orn = p.getDynamicsInfo(body, -1, physicsClientId=c)[3:5]
        com_pos, com_orn = p.multiplyTransforms(pos, orn, inertial_pos, inertial_orn)
        p.resetBasePositionAndOrientation(body, com_pos, com_orn, physicsClientId=c)

    def body_name(self, body: int) -> str:
        """The name a loaded body's URDF gives it (``<robot name=...>``)."""
        return self.p.getBodyInfo(body, physicsClientId=self.client)[1].decode()

    def touching(self, a: int, b: int, margin: float = 0.0) -> bool:
        return bool(self.p.getClosestPoints(a, b, margin, physicsClientId=self.client))

    def set_friction(self, body: int, friction: float) -> None:
        """Lateral friction of every link of ``body`` (base included)."""
        p, c = self.p, self.client
        for link in range(-1, p.getNumJoints(body, physicsClientId=c)):
            p.changeDynamics(body, link, lateralFriction=friction, physicsClientId=c)

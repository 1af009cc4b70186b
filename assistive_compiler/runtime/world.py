"""The PyBullet world of one compiled artifact, built once per environment.

:class:`World` owns a private DIRECT client for its whole life. It loads every body of the
manifest, looks every referenced link and joint up by name once, attaches tools, creates the
particles and saves the initial state; :meth:`World.restore` brings that state back in well under
a millisecond. It knows nothing about any particular task.

Per-body gravity on stock pybullet (compensating forces before each physics step) is
:class:`~.gravity.PerBodyGravity`'s part of the World; garments (cloth held by the robot) are
:class:`~.garments.HeldGarments`'s; the handles of loaded bodies and :data:`~.bodies.PARK` are
:mod:`.bodies`'.

Person self-collision: a person body whose manifest lists self-collision pairs is loaded with
``URDF_USE_SELF_COLLISION`` and only those link pairs collide (:meth:`World._set_self_collision`);
every other body loads as before. :attr:`World.after_physics_step`, when set, runs after each
physics step of :meth:`step_physics` (the person's limit enforcement).

Garments: an artifact with garments gets a deformable world (``RESET_USE_DEFORMABLE_WORLD``
before anything is loaded; its gravity is the spec's, as a soft body feels only the world's).

Frames: pybullet reports a base's pose at its centre of mass; :meth:`base_frame` and
:meth:`set_base_frame` convert to and from the URDF frame the manifest uses.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pybullet as pb

from ..artifact import Manifest
from ..bullet import connect, use_contact_breaking_threshold
from .bodies import PARK, BodyHandle
from .garments import HeldGarments
from .gravity import PerBodyGravity

FLOOR_HALF_M = 20.0  # the floor slab's half width, m: the scene sits near the origin


class World(PerBodyGravity, HeldGarments):
    """All bodies of an artifact in one pybullet DIRECT client."""

    def __init__(self, artifact_dir: str | Path, manifest: Manifest | None = None):
        self.dir = Path(artifact_dir)
        self.m = manifest or Manifest.read(self.dir)
        #: Called after every ``stepSimulation`` of :meth:`step_physics` when set (the person's
        #: joint-limit and arm-limit enforcement); None costs nothing.
        self.after_physics_step: Callable[[], None] | None = None
        self._build()

    def rebuild(self) -> None:
        """A fresh physics client with the same bodies under the same ids.

        ``restoreState`` brings back every pose and velocity but not all of Bullet's solver and
        collision caches, so after some history an episode can drift from the same seed's
        episode in a fresh world. Rebuilding (tens of milliseconds) makes it bit-identical.
        """
        self.close()
        self._build()

    def _build(self) -> None:
        self.client = connect(
            self.m.sim.contact_breaking_threshold, deformable=bool(self.m.garments)
        )  # cloth needs Bullet's deformable world
        c = self.client
        sim = self.m.sim
        pb.setPhysicsEngineParameter(
            numSolverIterations=sim.solver_iterations, deterministicOverlappingPairs=1, physicsClientId=c
        )

        # The floor: a slab, top face at z = 0, not a GEOM_PLANE. A plane's bounding box is
        # infinite, so every link in the world overlapped it in the broadphase and got a
        # narrowphase test each physics step (a tenth of a Scratch Itch step's physics); the slab
        # pairs only with what comes near the floor. Outside it (beyond ±FLOOR_HALF_M) is the
        # parking area, where nothing should touch anything.
        floor = pb.createCollisionShape(
            pb.GEOM_BOX,
            halfExtents=[FLOOR_HALF_M, FLOOR_HALF_M, 0.5],
            collisionFramePosition=[0, 0, -0.5],
            physicsClientId=c,
        )
        floor_visual = pb.createVisualShape(
            pb.GEOM_BOX, halfExtents=[5, 5, 0.0005], rgbaColor=[0.85, 0.85, 0.82, 1], physicsClientId=c
        )
        self.ground = pb.createMultiBody(0, floor, floor_visual, [0, 0, 0], physicsClientId=c)

        self.bodies: dict[str, BodyHandle] = {}
        welded = {att.body for att in self.m.tools if att.welded}
        for body in self.m.bodies:
            if body.name in welded:  # its links are the robot's: see _weld_handles
                continue
            flags = pb.URDF_USE_INERTIA_FROM_FILE
            self_collision = body.kind == "person" and bool(self.m.person.self_collision)
            if self_collision:
                flags |= pb.URDF_USE_SELF_COLLISION
            bid = pb.loadURDF(
                str(self.dir / body.urdf),
                body.position,
                body.orientation,
                useFixedBase=body.fixed_base,
                flags=flags,
                physicsClientId=c,
            )
            self.bodies[body.name] = self._handle(body.name, bid)
            if self_collision:
                self._set_self_collision(self.bodies[body.name])
            if body.friction is not None:
                for link in [-1, *range(pb.getNumJoints(bid, physicsClientId=c))]:
                    pb.changeDynamics(bid, link, lateralFriction=body.friction, physicsClientId=c)
            # Disable the default velocity motors so joints are free unless we drive them.
            joints = list(range(pb.getNumJoints(bid, physicsClientId=c)))
            if joints:
                pb.setJointMotorControlArray(
                    bid, joints, pb.VELOCITY_CONTROL, forces=[0.0] * len(joints), physicsClientId=c
                )

        self._weld_handles()
        self._skip_immovable_pairs()
        self.robot = self.bodies["robot"]
        self.variant_bodies = {v.name: self.bodies[v.body] for v in self.m.person.variants}
        self.active_variant = self.m.person.variants[0]
        self._attach_tools()
        self._create_particles()
        self._create_garments()
        self._set_gravity()
        self._set_stepping()
        visual_only = {
            b for g in self.garments for b in (g.soft_id, g.anchor_id)
        }  # garments are reset by reset_garments()
        self._all_bodies = [
            b for b in range(pb.getNumBodies(physicsClientId=c)) if b != self.ground and b not in visual_only
        ]
        # Bodies at rest would otherwise fall asleep after ~2 s; sleep is not part of a saved state,
        # so an episode would depend on how long the previous one left something resting.
        for bid in self._all_bodies:
            pb.changeDynamics(bid, -1, activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING, physicsClientId=c)
        self.initial_state = pb.saveState(physicsClientId=c)

    # -- construction --------------------------------------------------------------------------
    def _handle(self, name: str, bid: int) -> BodyHandle:
        c = self.client
        links = {pb.getBodyInfo(bid, physicsClientId=c)[0].decode(): -1}
        joints: dict[str, int] = {}
        for j in range(pb.getNumJoints(bid, physicsClientId=c)):
            info = pb.getJointInfo(bid, j, physicsClientId=c)
            joints[info[1].decode()] = j
            links[info[12].decode()] = j
        ipos, iorn = pb.getDynamicsInfo(bid, -1, physicsClientId=c)[3:5]
        return BodyHandle(name, bid, links, joints, pb.invertTransform(ipos, iorn))

    def _weld_handles(self) -> None:
        """A handle per welded tool on its links of the robot's multibody (the tool's root, on the
        fixed joint ``<tool>_grip``, and every link below it); the robot's handle keeps the rest.
        Both get a :attr:`BodyHandle.link_set`, so contacts and distances stay each one's own."""
        tools = [att for att in self.m.tools if att.welded]
        if not tools:
            return
        c, robot = self.client, self.bodies["robot"]
        parent = {j: pb.getJointInfo(robot.id, j, physicsClientId=c)[16] for j in robot.joints.values()}
        owner: dict[int, str] = {}
        for att in tools:
            root = robot.links[att.links["base"]]
            for link in sorted(parent):  # a child's index is larger than its parent's
                if link == root or owner.get(parent[link]) == att.body:
                    owner[link] = att.body
        for att in tools:
            mine = {link for link, tool in owner.items() if tool == att.body}
            self.bodies[att.body] = BodyHandle(
                att.body,
                robot.id,
                {name: i for name, i in robot.links.items() if i in mine},
                {name: j for name, j in robot.joints.items() if j in mine},
                ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
                base_link=robot.links[att.links["base"]],
                link_set=frozenset(mine),
            )
        self.bodies["robot"] = BodyHandle(
            "robot",
            robot.id,
            {name: i for name, i in robot.links.items() if i not in owner},
            {name: j for name, j in robot.joints.items() if j not in owner},
            robot.inertial_inv,
            link_set=frozenset(i for i in robot.links.values() if i not in owner),
        )

    def _skip_immovable_pairs(self) -> None:
        """No collision between links that can never move, of different bodies.

        Pybullet makes every link of a multibody that has a mass a dynamic collider, even one
        held by fixed joints to a fixed base (a supine person's hips kept as their own link for
        self-collision, lying on the mattress), and then computes and solves its contacts with the
        furniture every physics step: about ten contacts that move nothing and cost an eighth of an
        Arm Manipulation step. Those pairs are filtered out once, at build; contacts of anything
        that moves are unchanged, and no term reads a force between two immovable bodies. Only
        pairs with such a link get a filter: setting one re-inserts the bodies in the broadphase,
        which reorders the solver's contact rows, so scenes without such links keep their
        trajectories bit for bit.
        """
        c = self.client
        still: list[tuple[int, list[int]]] = [(self.ground, [-1])]
        for body in self.m.bodies:
            if not body.fixed_base:
                continue
            bid = self.bodies[body.name].id
            moving = {index for index, _ in self._moving_links(bid)}
            links = [
                index
                for index in range(-1, pb.getNumJoints(bid, physicsClientId=c))
                if index not in moving and pb.getCollisionShapeData(bid, index, physicsClientId=c)
            ]
            if links:
                still.append((bid, links))
        for i, (a, links_a) in enumerate(still):
            for b, links_b in still[i + 1 :]:
                for la in links_a:
                    for lb in links_b:
                        if la >= 0 or lb >= 0:  # two fixed bases are static colliders: Bullet never pairs them
                            pb.setCollisionFilterPair(a, b, la, lb, 0, physicsClientId=c)

    def _set_self_collision(self, handle: BodyHandle) -> None:
        """Self-collision of a person body (paper §III-A): every link pair off, then the pairs the
        compiler chose (``manifest.person.self_collision``, link names) on.

        The compiler lists only pairs between links that move relative to each other, of the
        reference's groups (an arm or leg against the rest), for the groups that move in the task,
        and leaves out pairs already touching at the rest pose; see
        :func:`assistive_compiler.compile.self_collision.person_self_collision`. Pybullet never collides
        a link with its direct parent (the ``URDF_USE_SELF_COLLISION`` default), nor does the list.
        """
        c, bid = self.client, handle.id
        links = sorted(handle.links.values())
        for i, a in enumerate(links):
            for b in links[i + 1 :]:
                pb.setCollisionFilterPair(bid, bid, a, b, 0, physicsClientId=c)
        for a, b in self.m.person.self_collision:
            if a in handle.links and b in handle.links:
                pb.setCollisionFilterPair(bid, bid, handle.links[a], handle.links[b], 1, physicsClientId=c)
        # Saved at its initial pose (free of self-contact, the compiler checked), not at zero angles
        # (a straight arm touches the hips): restore() runs a collision pass on the saved state.
        for v in self.m.person.variants:
            if v.body == handle.name:
                for name, q in v.initial_angles.items():
                    pb.resetJointState(bid, handle.joints[name], q, physicsClientId=c)

    def _attach_tools(self) -> None:
        c = self.client
        self.tool_constraints: dict[str, int] = {}
        for att in self.m.tools:
            if att.welded:  # already a part of the robot
                continue
            tool = self.bodies[att.body]
            parent = self.robot.links[att.parent_link]
            # Constraint frames are relative to centres of mass: convert from URDF link frames.
            p_inertial = pb.getDynamicsInfo(self.robot.id, parent, physicsClientId=c)[3:5]
            p_inv = pb.invertTransform(*p_inertial)
            parent_pos, parent_orn = pb.multiplyTransforms(p_inv[0], p_inv[1], att.position, att.orientation)
            child_pos, child_orn = tool.inertial_inv
            cid = pb.createConstraint(
                self.robot.id,
                parent,
                tool.id,
                -1,
                pb.JOINT_FIXED,
                [0, 0, 0],
                parent_pos,
                child_pos,
                parent_orn,
                child_orn,
                physicsClientId=c,
            )
            pb.changeConstraint(cid, maxForce=500, physicsClientId=c)
            self.tool_constraints[att.body] = cid
            for link in self.robot.links.values():
                for tl in tool.links.values():
                    pb.setCollisionFilterPair(self.robot.id, tool.id, link, tl, 0, physicsClientId=c)

    def _create_particles(self) -> None:
        c = self.client
        self.particles: dict[str, list[int]] = {}
        #: Per set that can rest in a container: one visual-only sphere per particle, drawn in
        for ps in self.m.particles:
            shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=ps.radius, physicsClientId=c)
            ids = []
            for i in range(ps.count):
                visual = pb.createVisualShape(
                    pb.GEOM_SPHERE, radius=ps.radius, rgbaColor=list(ps.colors[i]), physicsClientId=c
                )
                ids.append(
                    pb.createMultiBody(
                        ps.mass, shape, visual, [PARK[0] - 5.0 - 0.1 * i, PARK[1] + 1.0, PARK[2]], physicsClientId=c
                    )
                )
            self.particles[ps.name] = ids

    def _set_stepping(self) -> None:
        """One ``stepSimulation`` per physics step (each split into the spec's solver sub-steps).

        Not fused into one call of frame_skip × time_step: pybullet turns motor force limits into
        impulse limits and contact impulses into reported forces with the call's time step, so a
        fused call would make motors frame_skip times stronger and contact forces frame_skip times
        weaker than the spec says.
        """
        sim, c = self.m.sim, self.client
        pb.setTimeStep(sim.time_step, physicsClientId=c)
        pb.setPhysicsEngineParameter(numSubSteps=sim.sub_steps, physicsClientId=c)

    # -- per step ------------------------------------------------------------------------------
    def step_physics(self) -> None:
        """Advance one env step (frame_skip physics steps) with per-body gravity compensation."""
        after = self.after_physics_step
        garments = bool(self.garments)
        use_contact_breaking_threshold(self.client, self.m.sim.contact_breaking_threshold)  # process-wide in pybullet
        for _ in range(self.m.sim.frame_skip):
            self._apply_gravity_compensation()
            pb.stepSimulation(physicsClientId=self.client)
            if garments:  # the held frame moved with the hand: the anchor follows before the next step
                self.follow_grips()
            if after is not None:
                after()

    def set_asleep(self, handle: BodyHandle, asleep: bool) -> None:
        """Put a parked body to sleep, or wake it (and keep it from sleeping).

        Bullet skips a sleeping multibody's dynamics and the motor rows of its joints, which it
        builds every physics step whatever their force: the parked person variant of Scratch Itch
        cost 6% of the physics. Called at every reset for every variant, never left to Bullet's
        sleep timers, so an episode does not depend on the ones before it; a body parked far away
        touches nothing and so is never woken during an episode. Only for bodies at rest: waking
        does not give a multibody back the velocity it had.
        """
        flags = (
            (pb.ACTIVATION_STATE_ENABLE_SLEEPING | pb.ACTIVATION_STATE_SLEEP)
            if asleep
            else (pb.ACTIVATION_STATE_DISABLE_SLEEPING | pb.ACTIVATION_STATE_WAKE_UP)
        )
        pb.changeDynamics(handle.id, -1, activationState=flags, physicsClientId=self.client)

    # -- frames --------------------------------------------------------------------------------
    def base_frame(self, handle: BodyHandle):
        """World pose of a body's URDF base frame (a garment's: its held frame; a welded tool's: its
        root link's)."""
        if handle.base_link >= 0:
            return self.link_frame(handle, handle.base_link)
        com_pos, com_orn = pb.getBasePositionAndOrientation(
            handle.id if handle.pose_id is None else handle.pose_id, physicsClientId=self.client
        )
        return pb.multiplyTransforms(com_pos, com_orn, *handle.inertial_inv)

    def set_base_frame(self, handle: BodyHandle, pos, orn) -> None:
        """Place a body so that its URDF base frame is at (pos, orn); not a welded tool, which goes
        where the robot's hand goes."""
        if handle.base_link >= 0:
            raise ValueError(f"'{handle.name}' is welded to the robot: it moves with the robot's hand")
        inv = pb.invertTransform(*handle.inertial_inv)
        com_pos, com_orn = pb.multiplyTransforms(pos, orn, *inv)
        pb.resetBasePositionAndOrientation(handle.id, com_pos, com_orn, physicsClientId=self.client)

    def link_frame(self, handle: BodyHandle, link: int):
        if link == -1:
            return self.base_frame(handle)
        s = pb.getLinkState(handle.id, link, computeForwardKinematics=True, physicsClientId=self.client)
        return s[4], s[5]

    def restore(self) -> None:
        """Back to the saved initial state (poses, velocities), without the previous episode's contacts.

        ``restoreState`` does not drop the collision pipeline's cached contact manifolds, so every
        body is first moved apart and one collision pass drops the pairs before restoring again.
        Some solver state still survives (see :meth:`rebuild` for bit-exact replay).
        """
        c = self.client
        use_contact_breaking_threshold(c, self.m.sim.contact_breaking_threshold)  # process-wide in pybullet
        pb.restoreState(self.initial_state, physicsClientId=c)
        for k, bid in enumerate(self._all_bodies):
            pb.resetBasePositionAndOrientation(
                bid, (PARK[0] + 1000.0 + 10.0 * k, PARK[1], PARK[2]), (0, 0, 0, 1), physicsClientId=c
            )
        pb.performCollisionDetection(physicsClientId=c)
        pb.restoreState(self.initial_state, physicsClientId=c)

    def close(self) -> None:
        if self.client is not None and pb.isConnected(self.client):
            pb.disconnect(self.client)
        self.client = None

    def __del__(self):  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:
            pass

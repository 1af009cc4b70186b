"""The scripted baseline: move a tool point through the task's waypoints by inverse kinematics.

Each step it reads the world (privileged: true target positions), asks pybullet's IK for the arm
configuration that puts the moved point at the current waypoint with the tool's start
orientation (or the waypoint's own), and returns the joint-delta action that heads there (clipped to [−1, 1]). It
advances to the next waypoint within the waypoint's tolerance — or when it has stalled, stopped
getting closer (by default no gain of more than 2 mm in 10 steps; each waypoint's ``stall_steps``
and ``stall_progress_m``: an approach point the arm cannot quite reach should not end the
episode) — and holds the last one, or goes on from ``repeat_from`` (to rub back and
forth). A waypoint may sit off a surface-drawn target along its outward normal and along its limb,
and may turn the tool towards that target's surface (``face_normal_within_rad``: the smallest
rotation of the start orientation that brings the tool's pointing axis — end effector to moved
point — within that angle of the inward normal, so a spot on the far side of a limb is met tip
first rather than with the tool lying across the limb; with ``face_normal_level`` only about the
vertical, for a wrist that only yaws), and may be approached along a straight line
(``step_m``: IK aims at most that far ahead of the moved point) and turned slowly (``turn_step_rad``:
the orientation IK aims at turns at most that far each step). A robot's own script may damp
some arm joints in the IK (``ik_damping``, e.g. a slow shoulder). A waypoint's offset and
orientation may be in a point's link frame (``frame``: they turn with that link, R_world =
R_frame·R with R = Rz·Ry·Rx of its rpy), its offset may differ per person variant
(``offset_by_variant``), and its lane may follow a person link's surface (``surface``: the goal and
each look-ahead put on the link's shapes, :mod:`.surface_lane`). Works for any task and robot
whose manifest has a ``scripted`` section.

With ``trace=True`` it keeps a trace of its waypoint events (``run --trace``): each waypoint
reached or given up as stalled, and where the episode ended, with the goal, the distance left and
what the robot and its tools touched (see :meth:`ScriptedPolicy.end_episode`).
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb

from ..artifact import Script
from ..ik_options import ik_damping, ik_limits
from ..references import LinkPoint, TargetPoint
from ..rotation import quat_about, quat_conj, quat_mul, quat_rotate, quat_towards, vec_angle
from .surface_lane import onto_surface, shapes_of

# face_normal_level: a level tool's pointing axis is at least the normal's elevation from the inward
# normal whatever its yaw, so past 45° it meets the surface side first anyway and is not turned.
LEVEL_FACING_MAX_ELEVATION_RAD = math.radians(45)


class _Track:
    """One arm's part of the script: the moved point, its waypoints, its end effector and the
    action columns of its joints."""

    def __init__(self, env, script: Script, mount_link: str, joints: list[str]):
        snap, m = env.snap, env.manifest
        self.move = snap.point(script.move)
        waypoints = script.waypoints
        self.waypoints = [
            (snap.point(w.to), np.asarray(w.offset_m), w.tolerance_m, w.normal_offset_m, w.axis_offset_m)
            for w in waypoints
        ]
        self.orientations = [pb.getQuaternionFromEuler(w.rpy_rad) if w.rpy_rad else None for w in waypoints]
        # Offsets and orientations in a point's link frame (None: world), per-variant offsets, followed surfaces.
        self.frames = [snap.point(w.frame) if w.frame is not None else None for w in waypoints]
        self.variant_offsets = [{v: np.asarray(o) for v, o in w.offset_by_variant.items()} for w in waypoints]
        self.surfaces = [
            (snap.point(w.surface.link), {v: shapes_of(sh) for v, sh in w.surface.shapes.items()}, w.surface.step_m)
            if w.surface is not None
            else None
            for w in waypoints
        ]
        self.face_normal = [w.face_normal_within_rad for w in waypoints]
        self.face_level = [w.face_normal_level for w in waypoints]
        self.steps_m = [w.step_m for w in waypoints]
        self.turn_steps = [w.turn_step_rad for w in waypoints]
        # The stall rule per waypoint: moved on after stall_steps without stall_progress_m of progress.
        self.stall = [(w.stall_steps, w.stall_progress_m) for w in waypoints]
        self.labels = [w.to.target if isinstance(w.to, TargetPoint) else f"{w.to.body}.{w.to.link}" for w in waypoints]
        self.arm = ""  # "left arm " / "right arm " on a robot acting with both arms (trace lines)
        self.repeat_from = script.repeat_from
        self.ee_link = env.link_index("robot", mount_link)
        self.ee_point = snap.point(LinkPoint(body="robot", link=mount_link))
        order = list(m.robot.arm_joints)
        self.action_cols = [
            order.index(j) for j in joints
        ]  # columns among the arm joints (env.arm_idx, env.delta_scale)


class ScriptedPolicy:
    """Callable ``obs -> action`` bound to one :class:`~assistive_compiler.runtime.env.AssistiveEnv`.

    With a ``left`` section (a two-arm robot acting with both arms) the right arm follows the main
    waypoints and the left arm its own, each solved by its own IK call every step."""

    def __init__(self, env, trace: bool = False):
        m = env.manifest
        if m.scripted is None:
            from ..errors import SpecError

            raise SpecError.at(
                m.sources[0] if m.sources else m.task,
                f"task '{m.task}' has no scripted: section, so there is no "
                "scripted policy for it; use --policy random or zero, or add scripted: waypoints",
            )
        self.env = env
        links = m.robot.links
        if m.scripted.left is not None:
            self.tracks = [
                _Track(env, m.scripted, links["right_tool_mount"], list(m.joint_groups["robot.right_arm"].joints)),
                _Track(env, m.scripted.left, links["left_tool_mount"], list(m.joint_groups["robot.left_arm"].joints)),
            ]
            self.tracks[0].arm, self.tracks[1].arm = "right arm ", "left arm "
        else:
            self.tracks = [_Track(env, m.scripted, links["tool_mount"], list(m.robot.arm_joints))]
        #: With ``trace``: this episode's waypoint events so far, each a dict (see :meth:`_note`); None without.
        self.trace: list[dict] | None = [] if trace else None
        robot, c = env.body_id("robot"), env.client
        movable = [
            j
            for j in range(pb.getNumJoints(robot, physicsClientId=c))
            if pb.getJointInfo(robot, j, physicsClientId=c)[2] != pb.JOINT_FIXED
        ]
        self.movable = movable
        # Each arm joint with its followers: IK spreads a move over the group, the action is their mean.
        followers = m.robot.followers or {}
        for track in self.tracks:
            track.cols = [
                [movable.index(env.arm_idx[k])]
                + [
                    movable.index(env.joint_index("robot", f))
                    for f, lead in followers.items()
                    if lead == m.robot.arm_joints[k]
                ]
                for k in track.action_cols
            ]
        self.lo_all = [pb.getJointInfo(robot, j, physicsClientId=c)[8] for j in movable]
        self.hi_all = [pb.getJointInfo(robot, j, physicsClientId=c)[9] for j in movable]
        self.ranges = [max(h - link, 1e-3) for link, h in zip(self.lo_all, self.hi_all)]
        # A mobile base drives: IK moves its planar joints with the arm, and the wheel actions head
        # for the planar change it asks of the base (see :meth:`_wheels`).
        # The robot's own script may damp some arm joints (e.g. a slow shoulder).
        own = {env.joint_index("robot", name): value for name, value in (m.scripted.ik_damping or {}).items()}
        self.damping = ik_damping(movable, [], env.drive.idx if env.drive else [], own)
        self.drive_cols = [movable.index(j) for j in env.drive.idx] if env.drive else []
        self.arm_offset = 2 if env.drive else 0

    def _goal(self, track: _Track) -> tuple[np.ndarray, float]:
        """The track's current waypoint position (world, m) and tolerance: ``to`` plus the offset
        (this variant's, along the frame's axes), then off a surface target along its normal and
        limb, or put on the followed surface."""
        k = track.index
        to, offset, tol, along_normal, along_axis = track.waypoints[k]
        snap = self.env.snap
        if track.variant_offsets[k]:
            offset = track.variant_offsets[k].get(self.env.person_variant, offset)
        if track.frames[k] is not None:
            offset = quat_rotate(snap.orientation(track.frames[k]), offset)
        if track.surfaces[k] is not None:
            return self._on_surface(track, snap.position(to) + offset + along_axis * snap.axis(to))[0], tol
        return snap.position(to) + offset + along_normal * snap.normal(to) + along_axis * snap.axis(to), tol

    def _on_surface(self, track: _Track, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``p`` (world) put on the current waypoint's followed surface, ``normal_offset_m`` off it,
        and the surface's outward normal there (world, unit)."""
        link, shapes, _ = track.surfaces[track.index]
        snap = self.env.snap
        pos, orn = snap.position(link), snap.orientation(link)
        q, normal = onto_surface(shapes[self.env.person_variant], quat_rotate(quat_conj(orn), p - pos))
        q = q + track.waypoints[track.index][3] * normal
        return pos + quat_rotate(orn, q), quat_rotate(orn, normal)

    def _start_episode(self) -> None:
        snap = self.env.snap
        for track in self.tracks:
            # The moved point rides rigidly on the end effector: remember its pose in the EE frame,
            # and the orientation to keep.
            ee_pos, ee_orn = snap.position(track.ee_point), snap.orientation(track.ee_point)
            pt_pos, pt_orn = snap.position(track.move), snap.orientation(track.move)
            inv = pb.invertTransform(ee_pos.tolist(), ee_orn.tolist())
            track.point_in_ee = pb.multiplyTransforms(inv[0], inv[1], pt_pos.tolist(), pt_orn.tolist())
            track.keep_orn = pt_orn.tolist()
            # The tool's pointing axis (end effector → moved point), in the moved point's link frame.
            d = pt_pos - ee_pos
            d = d / max(float(np.linalg.norm(d)), 1e-9)
            track.axis_in_point = np.asarray(quat_rotate(quat_conj(pt_orn), d))
            track.index = 0
            track.best, track.since_best = float("inf"), 0
            track.noted = set()  # trace events noted for the current (held) waypoint
            track.aimed_orn = None  # the orientation last handed to IK on a slow turn (turn_step_rad)
        if self.trace is not None:
            self.trace = []

    @staticmethod
    def _facing(track: _Track, orn, inward: np.ndarray, within: float) -> list[float]:
        """``orn`` turned by the smallest rotation that brings the track's pointing axis within
        ``within`` (rad) of the unit vector ``inward`` (world); unchanged when it already is."""
        d = quat_rotate(np.asarray(orn), track.axis_in_point)
        angle = vec_angle(d, inward)
        if angle <= within:
            return list(orn)
        k = np.cross(d, inward)
        if np.linalg.norm(k) < 1e-6:  # pointing straight away from the surface: turn through the horizontal z × d
            k = np.cross(d, np.cross(np.array([0.0, 0.0, 1.0]), d))
            if np.linalg.norm(k) < 1e-6:
                k = np.cross(d, np.array([1.0, 0.0, 0.0]))
        k = k / np.linalg.norm(k)
        return quat_mul(quat_about(k, angle - within), np.asarray(orn)).tolist()

    @staticmethod
    def _yawing(track: _Track, orn, inward: np.ndarray, within: float) -> list[float]:
        """``orn`` turned about the vertical (world z) by the smallest angle that brings the
        horizontal part of the track's pointing axis within ``within`` (rad) of the horizontal part
        of ``inward`` (world); unchanged when it already is, or when ``inward`` is more than
        ``LEVEL_FACING_MAX_ELEVATION_RAD`` from the horizontal (no yaw meets that surface tip first)."""
        if math.hypot(inward[0], inward[1]) < math.cos(LEVEL_FACING_MAX_ELEVATION_RAD):
            return list(orn)
        d = quat_rotate(np.asarray(orn), track.axis_in_point)
        angle = math.atan2(inward[1], inward[0]) - math.atan2(d[1], d[0])
        angle = (angle + math.pi) % (2 * math.pi) - math.pi  # signed, in [-pi, pi): from the axis to the normal
        if abs(angle) <= within:
            return list(orn)
        turn = math.copysign(abs(angle) - within, angle if angle != -math.pi else 1.0)
        return quat_mul(quat_about((0.0, 0.0, 1.0), turn), np.asarray(orn)).tolist()

    def __call__(self, obs) -> np.ndarray:
        env = self.env
        if env.steps == 0:  # first action of an episode
            self._start_episode()
        c = env.client
        robot = env.body_id("robot")
        rest = [pb.getJointState(robot, j, physicsClientId=c)[0] for j in self.movable]
        action = np.zeros(env.action_space.shape, dtype=np.float32)
        for track in self.tracks:
            goal, tol = self._goal(track)
            error = float(np.linalg.norm(env.snap.position(track.move) - goal))
            stall_steps, progress = track.stall[track.index]
            if error < track.best - progress:
                track.best, track.since_best = error, 0
            else:
                track.since_best += 1
            last = track.index == len(track.waypoints) - 1
            reached, stalled = error <= tol, track.since_best >= stall_steps
            moves_on = (not last or track.repeat_from is not None) and (reached or stalled)
            if self.trace is not None and (moves_on or (reached or stalled)):
                self._note(track, "reached" if reached else "stalled", goal, moves_on)
            if moves_on:
                track.index = track.index + 1 if not last else track.repeat_from
                track.best, track.since_best = float("inf"), 0
                track.aimed_orn = None
                track.noted = set()
                goal, tol = self._goal(track)
            surface = track.surfaces[track.index]
            step = surface[2] if surface is not None else track.steps_m[track.index]
            if step is not None:  # a straight line from where the point is: IK aims at most step_m ahead
                here = env.snap.position(track.move)
                ahead = goal - here
                distance = float(np.linalg.norm(ahead))
                if distance > step:
                    goal = here + ahead * (step / distance)
            inward = None  # into the surface faced: the followed surface's, else the target's (read when needed)
            if surface is not None:  # the look-ahead put on the followed surface
                goal, outward = self._on_surface(track, goal)
                inward = -outward
            # End-effector pose that puts the moved point at the goal with the kept orientation.
            inv_pos, inv_orn = pb.invertTransform(*track.point_in_ee)
            orn = self._orientation(track)
            if track.face_normal[track.index] is not None:
                if inward is None:
                    inward = -env.snap.normal(track.waypoints[track.index][0])
                turn = self._yawing if track.face_level[track.index] else self._facing
                orn = turn(track, orn, inward, track.face_normal[track.index])
            turn_step = track.turn_steps[track.index]
            if turn_step is not None:  # a slow turn: the orientation handed to IK moves at most turn_step_rad a step,
                # from the tool's own orientation when the waypoint began (not from the lagging tool's, which a contact can stop)
                start = track.aimed_orn if track.aimed_orn is not None else env.snap.orientation(track.move)
                orn = track.aimed_orn = quat_towards(start, orn, turn_step).tolist()
            ee_pos, ee_orn = pb.multiplyTransforms(goal.tolist(), orn, inv_pos, inv_orn)
            sol = pb.calculateInverseKinematics(
                robot, track.ee_link, ee_pos, ee_orn, maxNumIterations=50, physicsClientId=c, **ik_limits(self, rest)
            )
            step = np.array([np.mean([sol[k] - rest[k] for k in group]) for group in track.cols])
            cols = track.action_cols
            action[[self.arm_offset + k for k in cols]] = np.clip(step / env.delta_scale[cols], -1.0, 1.0)
            if self.drive_cols and track is self.tracks[0]:
                action[:2] = self._wheels(sol, rest)
        return action

    def _orientation(self, track: _Track) -> list[float]:
        """The orientation the current waypoint asks of the moved point's link (world): its rpy in
        its frame (R_world = R_frame·R), or the tool's start orientation."""
        own = track.orientations[track.index]
        if own is None:
            return list(track.keep_orn)
        frame = track.frames[track.index]
        if frame is None:
            return list(own)
        return quat_mul(self.env.snap.orientation(frame), np.asarray(own)).tolist()

    def trace_report(self, seed: int | None) -> list[str]:
        """With ``trace``: the trace of the episode just played from ``seed`` (ended first, see
        :meth:`end_episode`), as ``render --trace`` and ``view --trace`` print it."""
        self.end_episode()
        assert self.trace is not None
        return [f"trace of the episode (seed {seed}):", *(f"  {event['line']}" for event in self.trace)]

    def end_episode(self) -> None:
        """With ``trace``: note where each arm stands when the episode ends (call it after the
        episode's last step; the event is ``ended``)."""
        if self.trace is not None:
            for track in self.tracks:
                self._note(track, "ended", self._goal(track)[0], False)

    def _note(self, track: _Track, event: str, goal: np.ndarray, moves_on: bool) -> None:
        """Add a trace event (``reached``, ``stalled`` or ``ended``) of ``track``'s current waypoint
        with its goal (world, m), once per visit of a waypoint that is held, as a dict: ``step``,
        ``arm``, ``waypoint`` (its index), ``to``, ``event``, ``goal_m``, ``point_m``, ``distance_m``,
        ``tolerance_m``, ``contacts`` (what the robot and its tools touch: ``tool–body:link``),
        ``moved_on`` and ``line`` (the event in words, one line)."""
        if event != "ended" and not moves_on:  # the held last waypoint: each event once
            if event in track.noted:
                return
            track.noted.add(event)
        env, k = self.env, track.index
        point = env.snap.position(track.move)
        distance = float(np.linalg.norm(point - goal))
        tol = track.waypoints[k][2]
        stall_steps, progress = track.stall[k]
        contacts = self._contacts()
        touching = ", ".join(contacts) if contacts else "nothing"
        where = f"waypoint {k} ({track.labels[k]})"
        if event == "reached":
            what = f"reached: {_cm(distance)} from its goal, within tolerance_m {_cm(tol)}"
        elif event == "stalled":
            why = (
                f"held back by contact with {touching}"
                if contacts
                else "out of reach, nothing touching the robot or its tool"
            )
            what = (
                f"stalled {_off(point, goal)}: {why} (no progress of more than {progress * 1000:g} mm "
                f"in {stall_steps} steps)"
            )
        else:
            what = f"was still the goal when the episode ended, {_off(point, goal)}"
        then = ""
        if moves_on:
            last = k == len(track.waypoints) - 1
            then = f"; on to waypoint {k + 1 if not last else track.repeat_from}"
        elif event != "ended":
            then = "; the last waypoint: held"
        touches = f"; touching {touching}" if contacts and event != "stalled" else ""
        line = (
            f"step {env.steps}: {track.arm}{where} {what}{then}; goal ({_xyz(goal)}) m, "
            f"point ({_xyz(point)}) m{touches}"
        )
        self.trace.append(
            {
                "step": int(env.steps),
                "arm": track.arm.replace(" arm ", "") or None,
                "waypoint": k,
                "to": track.labels[k],
                "event": event,
                "goal_m": [float(x) for x in goal],
                "point_m": [float(x) for x in point],
                "distance_m": distance,
                "tolerance_m": tol,
                "contacts": contacts,
                "moved_on": moves_on,
                "line": line,
            }
        )

    def _contacts(self) -> list[str]:
        """What the robot and the tools it holds touch now, each once as ``own–other:link`` (the
        other body by its spec name, with its link where it has several); particles left out."""
        env, c = self.env, self.env.client
        own = {env.body_id("robot")} | {env.body_id(t.body) for t in env.manifest.tools}
        skip = {p.name for p in env.manifest.particles}
        names = env.body_names()
        out: list[str] = []
        for a in sorted(own):
            for cp in pb.getContactPoints(bodyA=a, physicsClientId=c):
                b = cp[2]
                other = names.get(b, str(b))
                if b in own or other in skip:
                    continue
                if pb.getNumJoints(b, physicsClientId=c) > 0:
                    link = (
                        pb.getBodyInfo(b, physicsClientId=c)[0]
                        if cp[4] < 0
                        else pb.getJointInfo(b, cp[4], physicsClientId=c)[12]
                    ).decode()
                    other = f"{other}:{link}"
                label = f"{env.link_owner(a, cp[3])}–{other}"
                if label not in out:
                    out.append(label)
        return out

    def _wheels(self, sol, rest) -> np.ndarray:
        """Wheel actions (right, left) towards the base's planar change in the IK solution ``sol``
        from the joint positions ``rest``: forward along the heading and the turn, the sideways
        part dropped (the base cannot move sideways; the arm and later steps' IK make it up)."""
        dx, dy, dyaw = (sol[k] - rest[k] for k in self.drive_cols)
        return self.env.drive.wheels_towards(dx, dy, dyaw)


def _cm(metres: float) -> str:
    return f"{metres * 100:.1f} cm"


def _xyz(v) -> str:
    return ", ".join(f"{x:+.3f}" for x in v)


def _off(point: np.ndarray, goal: np.ndarray) -> str:
    """Where ``point`` is from ``goal`` in words: ``10.0 cm below its goal`` when one world axis
    holds most of the gap, else ``10.0 cm from its goal`` with the gap per axis."""
    d = point - goal
    distance = float(np.linalg.norm(d))
    if distance < 1e-9:
        return "at its goal"
    axis = int(np.argmax(np.abs(d)))
    if abs(d[axis]) >= 0.8 * distance:
        sign = "+" if d[axis] > 0 else "-"
        side = ("above" if sign == "+" else "below") if axis == 2 else f"off towards {sign}{'xy'[axis]} of"
        return f"{_cm(distance)} {side} its goal"
    return f"{_cm(distance)} from its goal (point − goal: {_xyz(d)} m)"

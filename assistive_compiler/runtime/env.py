"""The Gymnasium face of a compiled task: one generic environment for every task and robot.

* **Action** (robot): joint-position deltas of the arm in [−1, 1]; each env step the target is
  ``q_measured + frame_skip · action_scale · multiplier · clip(a)`` clamped to the joint limits,
  sent as one position-control command, then ``frame_skip`` physics steps run (the paper's 10 Hz
  control). A mobile robot's action starts with two wheel dimensions (:mod:`.drive`), and joints
  that follow an arm joint get its target change.
* **Observation**: the spec's features concatenated (float32).
* **Reward**: Σ weight·value over the reward terms (preference costs included);
  ``info["terms"]`` holds every term's unweighted value, ``info["total_force_on_human"]`` the
  contact force of robot and tools on the person (N), ``info["task_success"]`` 1 once the
  success criterion holds (``info["success_metric"]`` its aggregate so far).
* **Episodes** end by truncation after ``episode_steps`` (no early termination, as the paper).
* **The person** (:mod:`.human`): ``step()`` leaves it held, compliant or tremoring as the spec
  says; ``step_agents(robot_action, human_action)`` also drives its policy joints
  (``human_action_space``, the same delta rule) and returns ``observe_human()`` too — the
  co-optimisation face. Hard joint limits and pose-dependent arm limits then hold after every
  physics step.

``reset()`` restores a saved state and applies the manifest's reset events in order
(:mod:`.events`: person variant, randomised joint angles and impairment, surface targets, one of
the precomputed start configurations, furniture noise, floor friction, and the components'
episode starts) without reloading anything or solving IK (about a millisecond).

Reproducibility: ``reset(seed=s)`` gives the same episode for the same actions, bit for bit,
whatever the env did before — when the world has been reset or stepped since it was built, a
seeded reset rebuilds the physics client (tens of milliseconds), because Bullet keeps solver and
collision caches that no saved state covers (even a reset's collision pass leaves broadphase
pairs behind). Unseeded resets reuse the world; their episodes follow the seed sequence
but can differ in the last digits from a replay.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TypeVar

import gymnasium as gym
import numpy as np
import pybullet as pb

from ..artifact import Manifest, TermUse
from ..references import LinkPoint
from .binding import bind
from .component import EnvStep, Episode, EpisodeComponent
from .drive import BaseDriveControl, FollowerControl
from .events import Garments, TermMemories, bind_events
from .human import PersonController
from .markers import MarkerSystem
from .particles import ParticleSystem
from .snapshot import Snapshot
from .world import World

_T = TypeVar("_T")


def _named(table: Mapping[str, _T], name: str, missing: str, known: Iterable[str] | None = None) -> _T:
    """``table[name]``, or a KeyError that says ``missing`` and lists the names (``known``, else the
    table's) with a did-you-mean: the env's lookups by name."""
    if name in table:
        return table[name]
    from ..errors import did_you_mean, one_of

    names = list(table if known is None else known)
    raise KeyError(f"{missing}; expected one of {one_of(names)}{did_you_mean(name, names)}")


class Features:
    """One agent's observation: its bound features concatenated into a float32 vector."""

    def __init__(self, uses: list[TermUse], snap: Snapshot):
        self.fns = [bind(t, snap) for t in uses]
        bounds = np.cumsum([0] + [t.size for t in uses])
        self.slices = [slice(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]
        self.space = gym.spaces.Box(-np.inf, np.inf, (int(bounds[-1]),), np.float32)

    def __call__(self, snap: Snapshot) -> np.ndarray:
        obs = np.empty(self.space.shape, dtype=np.float32)
        for fn, where in zip(self.fns, self.slices):
            obs[where] = fn(snap)
        return obs


class AssistiveEnv(gym.Env):
    """A compiled assistive task as a Gymnasium environment (robot acting, person static).

    What other code may use (policies, recording, description, co-optimisation, the CLI):

    * the Gymnasium API and, for co-optimisation, :meth:`step_agents`, :meth:`observe_human`,
      ``human_action_space`` and ``human_observation_space``;
    * ``manifest`` (the compiled task), ``steps`` (env steps this episode), ``impairment`` (this
      episode's, drawn), ``success_threshold``;
    * the scene as it is now: :attr:`person_body`, :attr:`person_variant`, :attr:`active_variant`,
      :meth:`marker_state`, :meth:`particle_state`, :meth:`garment_nodes`, :attr:`arm_limit_reverts`,
      and the poses of bodies and links by name (:meth:`base_pose`, :meth:`link_pose`; URDF frames,
      world);
    * reading pybullet directly, by name: :attr:`client`, :meth:`body_id`, :meth:`link_index`,
      :meth:`joint_index`, :meth:`links`, :meth:`joints`, :meth:`particle_ids`, and back from ids
      to names, :meth:`body_names`;
    * ``physics_s``, the time its steps spent in physics (benchmarks);
    * for controllers, renders and benchmarks that work on the physics itself: ``world``
      (:class:`~.world.World`: the pybullet client, body handles, link frames), ``snap`` (the
      :class:`~.snapshot.Snapshot` every term reads, refreshed each step; read it, never write it),
      ``arm_idx`` (the arm's pybullet joint indices, in action order) and ``drive`` (a mobile
      base's :class:`~.drive.BaseDriveControl`, or None).

    The rest (components, bound terms, command tables) is the env's own.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        artifact_dir: str | Path,
        render_mode: str | None = None,
        render_size: tuple[int, int] = (480, 360),
        camera: dict | None = None,
        manifest: Manifest | None = None,
    ):
        """``camera``: eye / target (world m) / fov_deg overriding the task's camera in renders.
        ``manifest``: the artifact's manifest when the caller has just compiled or checked it
        (``compile_task``'s result); otherwise it is read and every file checked against it."""
        self.camera = camera
        #: Renders draw the end effector's, tools' and targets' frames with labels (``render --frames``).
        self.show_frames = False
        self.artifact_dir = Path(artifact_dir)
        self.manifest = m = manifest if manifest is not None else Manifest.read(self.artifact_dir, verify=True)
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.render_mode = render_mode
        self.render_size = render_size
        self.world = World(self.artifact_dir, m)
        self.snap = Snapshot(self.world)
        self.particles = ParticleSystem(self.world, self.snap)
        robot = self.world.robot
        self.arm_idx = [robot.joints[j] for j in m.robot.arm_joints]
        self.lower = np.array(m.robot.joint_lower)
        self.upper = np.array(m.robot.joint_upper)
        #: Per arm joint: target change per unit action per env step (rad or m).
        self.delta_scale = (
            m.robot.action_scale
            * m.sim.frame_skip
            * np.asarray(m.robot.action_multipliers or [1.0] * len(self.arm_idx))
        )
        self._gains = [m.robot.position_gain] * len(self.arm_idx)
        self._forces = [m.robot.max_force] * len(self.arm_idx)
        # Followers (moved with an arm joint) and a mobile base's drive, both commanded with the arm.
        self.drive = BaseDriveControl(self.world, m.robot.drive, m.sim.frame_skip) if m.robot.drive else None
        self.follow = FollowerControl(self.world, m.robot.followers or {}, list(m.robot.arm_joints), self.delta_scale)
        self._arm_slice = slice(2, None) if self.drive else slice(None)
        self._command_idx = self.arm_idx + self.follow.idx + (self.drive.idx if self.drive else [])
        self._command_gains = (
            self._gains + [m.robot.position_gain] * len(self.follow.idx) + (self.drive.gains if self.drive else [])
        )
        self._command_forces = (
            self._forces + [m.robot.max_force] * len(self.follow.idx) + (self.drive.forces if self.drive else [])
        )

        self.robot_features = Features(m.observations["robot"], self.snap)
        self.reward_fns = [(t.name, t.weight, bind(t, self.snap)) for t in m.reward]
        self.markers = MarkerSystem(self.world, self.snap)
        self.success_threshold = m.success.threshold
        self.tool_point = self.snap.point(LinkPoint(body="robot", link=m.robot.links["tool_mount"]))
        self._force_on_person = (
            [b.name for b in m.bodies if b.kind in ("robot", "tool")] + [g.name for g in m.garments],
            ["person"],
        )
        self.observation_space = self.robot_features.space
        self.action_space = gym.spaces.Box(-1.0, 1.0, (m.robot.action_size,), np.float32)
        self.steps = 0
        #: Wall seconds spent in physics (``stepSimulation`` and its per-step forces) by this env's
        #: steps since it was built: a benchmark's step minus this is the env's own cost.
        self.physics_s = 0.0
        self.success_metric: float | None = None
        #: Whether the world has seen anything since it was built (a reset runs collision
        #: detection, a step physics): a seeded reset then rebuilds it, to replay bit for bit.
        self._used = False
        # The person: holds, impairments, the human agent's policy joints (see runtime/human.py).
        self.human = PersonController(self.world, m, self.artifact_dir)
        n_human = len(m.person.policy_joints)
        self.human_action_space = gym.spaces.Box(-1.0, 1.0, (n_human,), np.float32) if n_human else None
        self.human_features = Features(m.observations.get("human", []), self.snap)
        self.human_observation_space = self.human_features.space
        #: The parts with per-episode state, in the order each env step runs them (:mod:`.component`).
        self.components: dict[str, EpisodeComponent] = {
            "person": self.human,
            "particles": self.particles,
            "markers": self.markers,
            "garments": Garments(self.world),
            "reward_terms": TermMemories([fn for _, _, fn in self.reward_fns]),
        }
        self._stepped = list(self.components.values())
        #: What a reset does, in the manifest's order (:mod:`.events`).
        self.events = bind_events(self, m.events)

    @classmethod
    def from_spec(
        cls, spec: str | Path, robot: str | None = None, out_dir: str | Path | None = None, library=None, **kwargs
    ) -> AssistiveEnv:
        """Compile ``spec`` for ``robot`` (a cache hit when unchanged) and build the env.
        ``library``: extra part directories (see :func:`assistive_compiler.library.Library.for_spec`)."""
        from ..compile.compiler import compile_task

        return cls.from_compiled(compile_task(spec, robot, out_dir, library=library), **kwargs)

    @classmethod
    def from_compiled(cls, result, **kwargs) -> AssistiveEnv:
        """The env of ``result`` (a :class:`~assistive_compiler.compile.compiler.CompileResult`),
        on the manifest it carries: the artifact was just written or checked, so it is not read again."""
        return cls(result.out_dir, manifest=result.manifest, **kwargs)

    # -- Gymnasium API ------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Restore the saved world and apply the manifest's reset events in order (:mod:`.events`).
        ``options["person_variant"]`` (a variant's name) chooses the person body."""
        super().reset(seed=seed)
        if seed is not None and self._used:
            self.world.rebuild()
        self._used = True
        self.world.restore()
        episode = Episode(self.np_random, options or {})
        for event in self.events:
            event(episode)
        assert episode.impairment is not None
        self.impairment = episode.impairment
        m = self.manifest
        if m.success.fraction_of is not None:
            self.success_threshold = m.success.threshold * self.markers.count(m.success.fraction_of)
        self.steps = 0
        self.success_metric = None
        self.snap.actions = {"robot": np.zeros(m.robot.action_size), "human": np.zeros(0)}
        self._set_robot_base_frame()
        self.snap.set_frame("person_base", *self.world.base_frame(self.world.variant_bodies[episode.variant.name]))
        self.snap.refresh()
        return self._observe(), episode.info()

    def command_start(self, joints: list[float]) -> None:
        """The arm at ``joints`` (rad, action order), its followers with it and the wheels at 0, at
        rest, with position-control targets there (a reset's robot start)."""
        w, c = self.world, self.world.client
        q0 = joints + self.follow.start(joints) + ([0.0, 0.0, 0.0] if self.drive else [])
        for i, q in zip(self._command_idx, q0):
            pb.resetJointState(w.robot.id, i, q, physicsClientId=c)
        pb.setJointMotorControlArray(
            w.robot.id,
            self._command_idx,
            pb.POSITION_CONTROL,
            targetPositions=q0,
            positionGains=self._command_gains,
            forces=self._command_forces,
            physicsClientId=c,
        )

    def step(self, action):
        """One env step of the robot; the person holds (or tremors) as the spec says."""
        return self._step(action, None)

    def step_agents(self, robot_action, human_action):
        """One env step of both agents (co-optimisation): ``human_action`` in ``human_action_space``
        drives the person's policy joints (see :mod:`.human`); None makes it a plain :meth:`step`.
        Returns (robot observation, human observation, reward, terminated, truncated, info)."""
        obs, reward, terminated, truncated, info = self._step(robot_action, human_action)
        return obs, self.observe_human(), reward, terminated, truncated, info

    def observe_human(self) -> np.ndarray:
        """The person's observation: the spec's human features concatenated (float32)."""
        return self.human_features(self.snap)

    def _step(self, action, human_action):
        m, w, c = self.manifest, self.world, self.world.client
        raw = np.asarray(action, dtype=np.float64).reshape(-1)
        if raw.shape != self.action_space.shape:
            raise ValueError(f"action must have shape {self.action_space.shape}, got {raw.shape}")
        q = np.array([s[0] for s in pb.getJointStates(w.robot.id, self.arm_idx, physicsClientId=c)])
        # np.minimum/np.maximum: np.clip's result, without its ~6 µs of call overhead.
        clipped = np.minimum(np.maximum(raw, -1.0), 1.0)
        arm_action = clipped[self._arm_slice]
        target = np.minimum(np.maximum(q + self.delta_scale * arm_action, self.lower), self.upper).tolist()
        if len(self._command_idx) > len(self.arm_idx):  # followers and a drive, in one command with the arm
            target += self.follow.targets(arm_action) + (self.drive.targets(clipped[:2]) if self.drive else [])
        pb.setJointMotorControlArray(
            w.robot.id,
            self._command_idx,
            pb.POSITION_CONTROL,
            targetPositions=target,
            positionGains=self._command_gains,
            forces=self._command_forces,
            physicsClientId=c,
        )
        # The person: held / tremoring without a human action, else its policy joints act (runtime/human.py).
        human = None if human_action is None else np.asarray(human_action, dtype=np.float64).reshape(-1)
        self.snap.actions["human"] = np.zeros(0) if human is None else human
        step = EnvStep(self.steps, human)
        for component in self._stepped:
            component.before_physics(step)
        t0 = time.perf_counter()
        w.step_physics()
        self.physics_s += time.perf_counter() - t0
        self.steps += 1
        self.snap.actions["robot"] = raw
        if self.drive:  # robot_base observations are in the moving base's frame
            self._set_robot_base_frame()
        self.snap.refresh()
        for component in self._stepped:
            component.after_step()

        values = {name: float(fn(self.snap)) for name, _, fn in self.reward_fns}
        reward = float(sum(weight * values[name] for name, weight, _ in self.reward_fns))
        metric = self._aggregate(values[m.success.term])
        info = {
            "terms": values,
            "total_force_on_human": self.snap.contact_force(*self._force_on_person),
            "task_success": int(metric >= self.success_threshold),
            "success_metric": metric,
        }
        truncated = self.steps >= m.sim.episode_steps
        return self._observe(), reward, False, truncated, info

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        from .camera import render_rgb

        return render_rgb(self, *self.render_size, view=self.camera)

    def close(self):
        self.world.close()

    # -- the scene as it is now (recording, description, co-optimisation) ----------------------
    @property
    def person_body(self) -> str:
        """Body name of this episode's person variant (``person_<variant>``)."""
        return self.world.active_variant.body

    @property
    def active_variant(self):
        """This episode's person variant as the manifest describes it
        (:class:`~assistive_compiler.artifact.PersonVariant`: its body, movable joints, markers, surfaces)."""
        return self.world.active_variant

    @property
    def person_variant(self) -> str:
        """This episode's person variant (e.g. ``male_50th``)."""
        return self.world.active_variant.name

    @property
    def client(self) -> int:
        """The pybullet physics client of this env's world: pass it as ``physicsClientId`` to read
        the simulation directly (tools, tests). Writing through it bypasses the env's bookkeeping."""
        return self.world.client

    def body_id(self, name: str) -> int:
        """The pybullet body id of the scene's body ``name``: ``robot``, ``person`` (this episode's
        variant), a variant's own name (``person_<variant>``), a tool or a piece of furniture. A
        tool welded to the robot (``manifest.tools[].welded``) has the robot's id; its links
        (:meth:`links`) are links of that body."""
        return self._body(name).id

    def link_index(self, body: str, link: str) -> int:
        """The pybullet link index of ``link`` of the body ``name`` (as :meth:`body_id`); −1 is the
        base link. Links merged at compile time have none (their frames ride on the link they joined)."""
        return _named(self._body(body).links, link, f"{body} has no link '{link}'")

    def joint_index(self, body: str, joint: str) -> int:
        """The pybullet joint index of ``joint`` of the body ``body`` (as :meth:`body_id`): any joint
        of its compiled URDF, welded (fixed) ones included; a merged link's joint is gone."""
        return _named(self._body(body).joints, joint, f"{body} has no joint '{joint}'")

    def links(self, body: str) -> dict[str, int]:
        """Every link of the body ``body`` (as :meth:`body_id`) that survived the compile-time merge,
        by name: its pybullet link index, −1 for the base (a copy)."""
        return dict(self._body(body).links)

    def joints(self, body: str) -> dict[str, int]:
        """Every joint of the body ``body`` (as :meth:`body_id`) in its compiled URDF, by name: its
        pybullet joint index (a copy)."""
        return dict(self._body(body).joints)

    def link_pose(self, body: str, link: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """World pose of ``link``'s URDF frame (m; quaternion x, y, z, w), the base link's too (not
        pybullet's centre-of-mass frame). ``body`` and ``link`` as :meth:`link_index`."""
        handle = self._body(body)
        return self.world.link_frame(handle, _named(handle.links, link, f"{body} has no link '{link}'"))

    def base_pose(self, body: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """World pose of the body's URDF base frame (m; quaternion x, y, z, w): where the spec
        places it, not pybullet's centre-of-mass frame."""
        return self.world.base_frame(self._body(body))

    def particle_ids(self, name: str) -> list[int]:
        """The pybullet body ids of particle set ``name``'s particles, in the set's order (a copy)."""
        return list(_named(self.world.particles, name, f"no particle set '{name}' in this scene"))

    def body_names(self) -> dict[int, str]:
        """Pybullet body id → the name a spec uses: every person variant is ``person``, each
        particle its set's name, the floor ``ground`` (e.g. to name the bodies of contact points).
        A welded tool's links are the robot's body: :meth:`link_owner` tells them apart."""
        w = self.world
        names = {h.id: name for name, h in w.bodies.items() if h.base_link == -1}
        names.update({w.variant_bodies[v.name].id: "person" for v in self.manifest.person.variants})
        for set_name, ids in w.particles.items():
            names.update({bid: set_name for bid in ids})
        names[w.ground] = "ground"
        return names

    def link_owner(self, body_id: int, link: int) -> str:
        """The name a spec uses for link ``link`` of pybullet body ``body_id``: as :meth:`body_names`,
        except that a welded tool's links are the tool's (e.g. to name a contact point's bodies)."""
        for name, h in self.world.bodies.items():
            if h.base_link >= 0 and h.id == body_id and link in (h.link_set or ()):
                return name
        return self.body_names().get(body_id, str(body_id))

    def _body(self, name: str):
        """The world's handle of body ``name`` (``person``: this episode's variant); a wrong name
        lists the scene's bodies."""
        key = self.person_body if name == "person" else name
        bodies = self.world.bodies
        return _named(bodies, key, f"no body '{key}' in this scene", known=["person", *bodies])

    def marker_state(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Marker set ``name``: every marker's position, (N, 3) world m (cleared ones too), and
        which are not cleared yet, (N,) bool (a copy)."""
        return self.markers.positions(name), self.markers.remaining[name].copy()

    def particle_state(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Particle set ``name``: where each particle appears, (N, 3) world m (removed ones are
        parked far away), and which are still in play, (N,) bool (a copy)."""
        return self.particles.shown_positions(name), self.particles.active[name].copy()

    def garment_nodes(self) -> dict[str, np.ndarray]:
        """Each garment's simulation-mesh node positions, (n, 3) world m."""
        return {g.name: self.world.garment_nodes(g) for g in self.world.garments}

    @property
    def arm_limit_reverts(self) -> int:
        """How often this episode a person's arm was put back inside its pose-dependent limits."""
        return self.human.reverts

    # -- helpers -------------------------------------------------------------------------------
    def _set_robot_base_frame(self) -> None:
        """The robot_base frame: the moving base link of a mobile robot, else the body's base frame."""
        w = self.world
        frame = w.link_frame(w.robot, self.drive.base_link) if self.drive else w.base_frame(w.robot)
        self.snap.set_frame("robot_base", *frame)

    def _observe(self) -> np.ndarray:
        return self.robot_features(self.snap)

    def _aggregate(self, value: float) -> float:
        """Fold this step's value of the success term into the episode's aggregate."""
        agg, metric = self.manifest.success.aggregate, self.success_metric
        if metric is None or agg == "last":
            metric = value
        elif agg == "sum":
            metric += value
        elif agg == "max":
            metric = max(metric, value)
        else:
            metric = min(metric, value)
        self.success_metric = metric
        return metric

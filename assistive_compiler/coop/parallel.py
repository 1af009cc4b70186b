"""The PettingZoo face of a compiled task: the robot and the person as two learning agents.

:class:`AssistiveParallelEnv` is a PettingZoo ``ParallelEnv`` over one
:class:`~assistive_compiler.runtime.env.AssistiveEnv` (paper §V-B, co-optimisation):

* **Agents** ``robot`` and ``human``, both live for the whole episode; both are truncated together
  after ``sim.episode_steps`` env steps (no early termination, as the paper).
* **Spaces** from the spec: the robot's are the single-agent env's; the human's action is one
  joint-position delta in [−1, 1] per ``person.control.policy_joints`` (4 for the head tasks, 10
  for the arm tasks) and its observation the spec's ``observations.human`` features (float32).
* **Reward** shared, as the reference: both agents get the same Σ weight·value (its action
  penalty is the norm of the concatenated robot and human action); each agent's ``infos`` entry
  carries ``terms``, ``task_success``, ``success_metric``, ``total_force_on_human``, and the
  human's also ``arm_limit_reverts`` (pose-dependent arm-limit reverts so far this episode).
* **The acting person obeys the body model** at every physics sub-step (runtime/human.py): hard
  and γ-scaled joint limits, the pose-dependent arm limits, self-collision, weakness and tremor.
  ``actions["human"] = None`` makes the person hold still for that step (the static person of the
  single-agent task).
* **Determinism**: ``reset(seed=s)`` replays both agents' episodes bit for bit for the same actions.
* ``state()`` is the robot's and the human's observation concatenated (``state_space``), for
  centralised critics; ``render()`` gives an RGB array with ``render_mode="rgb_array"``.
"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
from pettingzoo import ParallelEnv

from ..artifact import AGENTS
from ..errors import Problem, SpecError, did_you_mean
from ..runtime.env import AssistiveEnv

__all__ = ["AGENTS", "AssistiveParallelEnv", "parallel_env", "check_coop_spec", "coop_name"]


def coop_name(gym_id: str) -> str:
    """The co-optimisation name of a single-agent Gymnasium id, the reference's naming:
    ``assistive_compiler/FeedingJaco-v1`` → ``FeedingJacoHuman-v1``."""
    base, _, version = gym_id.rpartition("/")[2].rpartition("-")
    return f"{base}Human-{version}"


class AssistiveParallelEnv(ParallelEnv):
    """A compiled task with the robot and the person as agents (PettingZoo parallel API)."""

    metadata = {
        "name": "assistive_compiler_coop",
        "render_modes": ["rgb_array"],
        "render_fps": 10,
        "is_parallelizable": True,
    }

    def __init__(
        self, artifact_dir: str | Path, render_mode: str | None = None, render_size: tuple[int, int] = (480, 360)
    ):
        env = AssistiveEnv(artifact_dir, render_mode=render_mode, render_size=render_size)
        if env.human_action_space is None:
            env.close()
            raise ValueError(
                f"{artifact_dir}: the person has no policy joints (person.control.policy_joints is empty), "
                "so it cannot act as an agent; list the joint groups a human policy moves in the spec"
            )
        #: The single-agent env underneath (the same world; its ``step`` is the static person's task).
        self.env = env
        m = env.manifest
        from ..gym_ids import TASK_ID

        self.metadata = {
            **type(self).metadata,
            "name": coop_name(m.gym_id) if m.gym_id != TASK_ID else f"{m.task}_{m.robot_name}_human",
        }
        self.render_mode = render_mode
        self.possible_agents: list[str] = list(AGENTS)
        self.agents: list[str] = []
        self.observation_spaces = {"robot": env.observation_space, "human": env.human_observation_space}
        self.action_spaces = {"robot": env.action_space, "human": env.human_action_space}
        size = sum(int(s.shape[0]) for s in self.observation_spaces.values())
        self.state_space = gym.spaces.Box(-np.inf, np.inf, (size,), np.float32)
        self._obs: dict[str, np.ndarray] = {}

    @classmethod
    def from_spec(
        cls, spec: str | Path, robot: str | None = None, out_dir: str | Path | None = None, **kwargs
    ) -> AssistiveParallelEnv:
        """Check that ``spec`` gives the person something to control (a located :class:`SpecError`
        if not), compile it for ``robot`` (a cache hit when unchanged) and build the env."""
        from ..compile.compiler import compile_task
        from ..spec.load import load_spec

        check_coop_spec(load_spec(spec))
        return cls(compile_task(spec, robot, out_dir).out_dir, **kwargs)

    # -- PettingZoo API ---------------------------------------------------------------------------
    def observation_space(self, agent: str) -> gym.spaces.Box:
        return self.observation_spaces[agent]

    def action_space(self, agent: str) -> gym.spaces.Box:
        return self.action_spaces[agent]

    def reset(self, seed: int | None = None, options: dict | None = None):
        obs, info = self.env.reset(seed=seed, options=options)
        self.agents = list(self.possible_agents)
        self._obs = {"robot": obs, "human": self.env.observe_human()}
        return dict(self._obs), {"robot": info, "human": dict(info)}

    def step(self, actions: dict):
        """One env step of both agents: ``actions`` maps 'robot' and 'human' to their actions
        (``actions['human']`` may be None: the person holds still this step)."""
        if not self.agents:
            raise RuntimeError(
                "step() called with no live agents: the episode ended (or never began); call reset() first"
            )
        unknown = [a for a in actions if a not in self.possible_agents]
        if unknown:
            raise ValueError(
                f"unknown agent '{unknown[0]}' in actions; expected 'robot' and 'human'{did_you_mean(str(unknown[0]), self.possible_agents)}"
            )
        missing = [a for a in self.possible_agents if a not in actions]
        if missing:
            raise ValueError(
                f"actions has no entry for '{missing[0]}': give both 'robot' and 'human' an action "
                "(actions['human'] = None holds the person still)"
            )
        robot_obs, human_obs, reward, terminated, truncated, info = self.env.step_agents(
            actions["robot"], actions["human"]
        )
        self._obs = {"robot": robot_obs, "human": human_obs}
        done = terminated or truncated
        if done:
            self.agents = []
        agents = self.possible_agents
        infos = {"robot": info, "human": {**info, "arm_limit_reverts": self.env.arm_limit_reverts}}
        return (
            dict(self._obs),
            dict.fromkeys(agents, reward),
            dict.fromkeys(agents, terminated),
            dict.fromkeys(agents, truncated),
            infos,
        )

    def state(self) -> np.ndarray:
        """The robot's and the human's current observations, concatenated (float32)."""
        if not self._obs:
            raise RuntimeError("state() before reset()")
        return np.concatenate([self._obs["robot"], self._obs["human"]])

    def render(self):
        return self.env.render()

    def close(self):
        self.env.close()


def check_coop_spec(loaded) -> None:
    """Raise a located :class:`SpecError` unless the loaded spec gives the person joints to
    control and something to observe: co-optimisation needs both."""
    spec, smap = loaded.spec, loaded.smap
    problems = []
    if not spec.person.control.policy_joints:
        where = ("person", "control", "policy_joints")
        problems.append(
            Problem(
                smap.value(where if where in smap.values else where[:2]),
                "person.control.policy_joints: the person controls no joints, so it cannot be a co-optimisation "
                "agent; list the joint groups a human policy moves, e.g. [person.head] or [person.right_arm]",
            )
        )
    if not spec.observations.human:
        problems.append(
            Problem(
                smap.value(("observations", "human")),
                "observations.human: the person observes nothing, so it cannot be a co-optimisation agent; "
                "list its observation terms (see `assistive-compiler schema --terms`)",
            )
        )
    if problems:
        raise SpecError(problems)


def parallel_env(
    spec: str | Path,
    robot: str | None = None,
    render_mode: str | None = None,
    out_dir: str | Path | None = None,
    **kwargs,
) -> AssistiveParallelEnv:
    """The co-optimisation env of the task spec at ``spec`` for ``robot`` (compiled first; a cache
    hit when unchanged): ``assistive_compiler.parallel_env("specs/tasks/feeding.yaml", robot="jaco")``."""
    return AssistiveParallelEnv.from_spec(spec, robot=robot, out_dir=out_dir, render_mode=render_mode, **kwargs)

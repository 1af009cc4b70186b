"""Co-optimisation (paper §V-B): the robot and the person as two learning agents on a shared reward.

* :func:`parallel_env` — a PettingZoo ``ParallelEnv`` of any task spec and robot;
* :func:`make` / :func:`ids` — the shipped tasks by name, ``<Task><Robot>Human-v1`` (30);
* :class:`FixedPartner` — one agent as a plain Gymnasium env against a fixed partner policy;
* :func:`rollout_coop`, :func:`bench_coop` — episodes and speed (the CLI's ``run --coop``, ``bench --coop``).
"""

from .parallel import AGENTS, AssistiveParallelEnv, check_coop_spec, coop_name, parallel_env
from .partner import FixedPartner
from .policies import HUMAN_POLICIES, ROBOT_POLICIES, agent_policy
from .registry import ids, make, spec_of
from .rollout import bench_coop, rollout_coop

__all__ = [
    "AGENTS",
    "AssistiveParallelEnv",
    "parallel_env",
    "check_coop_spec",
    "coop_name",
    "make",
    "ids",
    "spec_of",
    "FixedPartner",
    "agent_policy",
    "ROBOT_POLICIES",
    "HUMAN_POLICIES",
    "rollout_coop",
    "bench_coop",
]

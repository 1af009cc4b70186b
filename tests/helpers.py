"""Small helpers shared by test modules: where a needle sits in a spec's text (``LINE:COL``, as
the CLI reports locations), an env of a spec compiled into a fresh directory, and the check that
an exported co-optimised pair acts as its checkpoint, training the reach example, and reads of the person and a mobile base
through the env's API."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pybullet as pb

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.runtime.env import AssistiveEnv


def at(text: str, needle: str, occurrence: int = 1) -> str:
    """``LINE:COL`` (1-based) of the ``occurrence``-th ``needle`` in ``text``."""
    index = -1
    for _ in range(occurrence):
        index = text.index(needle, index + 1)
    line = text.count("\n", 0, index) + 1
    column = index - (text.rfind("\n", 0, index) + 1) + 1
    return f"{line}:{column}"


#: The reach example (specs/examples/reach.yaml): a small task the training tests learn quickly.
REACH = Path(__file__).resolve().parents[1] / "specs" / "examples" / "reach.yaml"


def train_reach(config: Path, out: Path, *extra: str) -> None:
    """``train`` the reach example for Jaco with ``config`` into ``out`` (quiet), and check it succeeded."""
    from assistive_compiler.cli import main

    argv = ["train", str(REACH), "--robot", "jaco", "--config", str(config), "--out", str(out), "--quiet", *extra]
    assert main(argv) == 0


def compiled_env(tmp_path_factory, spec: Path, robot: str):
    """For a module fixture (``yield from``): ``spec`` compiled for ``robot`` into a fresh
    directory, its env yielded and closed afterwards."""
    name = f"{Path(spec).stem}-{robot}"
    env = AssistiveEnv(compile_task(spec, robot, tmp_path_factory.mktemp(name) / name).out_dir)
    yield env
    env.close()


def cli(*args: str, cwd: Path | None = None, env: dict | None = None, timeout: float = 600):
    """The real ``assistive-compiler`` command in a subprocess: (exit status, stdout, stderr).
    ``env`` entries are added to the current environment."""
    import os
    import subprocess
    import sys

    proc = subprocess.run(
        [sys.executable, "-m", "assistive_compiler.cli", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=os.environ | (env or {}),
    )
    return proc.returncode, proc.stdout, proc.stderr


def assert_each_agent_acts_on_its_own_observation(pair, sizes: tuple[int, int, int, int]) -> None:
    """A co-optimised checkpoint ``pair`` ((robot_obs, human_obs) -> (a_robot, a_human)) whose
    actors read only their own agent's observation: changing one agent's observation changes that
    agent's action and leaves the other's as it was; each agent alone (``pair.agent``) acts as in
    the pair. ``sizes``: robot and person observation sizes, robot and person action sizes."""
    import numpy as np

    robot_obs, human_obs, robot_act, human_act = sizes
    rng = np.random.default_rng(0)
    o_robot, o_human = rng.normal(size=robot_obs).astype(np.float32), rng.normal(size=human_obs).astype(np.float32)
    a_robot, a_human = pair(o_robot, o_human)
    assert a_robot.shape == (robot_act,) and a_human.shape == (human_act,)
    other_robot, other_human = pair(o_robot, o_human + 3.0)
    assert np.array_equal(other_robot, a_robot) and not np.allclose(other_human, a_human)
    other_robot, other_human = pair(o_robot + 3.0, o_human)
    assert np.array_equal(other_human, a_human) and not np.allclose(other_robot, a_robot)
    assert np.array_equal(pair.agent("robot")(o_robot), a_robot)
    assert np.array_equal(pair.agent("human")(o_human), a_human)


def assert_exported_pair_acts_as(checkpoint_pair, exported, artifact: Path, seed: int = 7) -> None:
    """On the observations of a real co-optimised episode of ``artifact`` (seed ``seed``, played by
    ``checkpoint_pair``), each agent of the ``exported`` pair acts as the checkpoint's, to float32
    precision. (Their episode returns may still differ by a point: the food's contacts amplify a
    1e-6 action difference.)"""
    import numpy as np

    from assistive_compiler.training.trained.evaluate import play_episodes

    seen: dict[str, list] = {"robot": [], "human": []}

    class Recorded:
        def agent(self, name):
            act = checkpoint_pair.agent(name)
            return lambda obs: (seen[name].append(obs), act(obs))[1]

    play_episodes(artifact, Recorded(), True, 1, seed)
    for name, observations in seen.items():
        assert len(observations) > 50
        worst = max(np.abs(exported.agent(name)(o) - checkpoint_pair.agent(name)(o)).max() for o in observations)
        assert worst < 1e-4, (name, worst)


def person(env: AssistiveEnv) -> SimpleNamespace:
    """This episode's person body: its pybullet id and its links and joints by name."""
    return SimpleNamespace(id=env.body_id("person"), links=env.links("person"), joints=env.joints("person"))


def drive_state(env: AssistiveEnv) -> np.ndarray:
    """A mobile base's planar joints (x, y m; yaw rad) as pybullet reads them."""
    return np.array([s[0] for s in pb.getJointStates(env.body_id("robot"), env.drive.idx, physicsClientId=env.client)])

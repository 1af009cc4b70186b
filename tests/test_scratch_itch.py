"""Scratch Itch's scripted baseline on a long arm: the tip goes round the limb to the spot."""

from __future__ import annotations

import numpy as np
import pytest

from assistive_compiler.paths import specs_dir
from helpers import compiled_env

SCRATCH_ITCH = specs_dir() / "tasks" / "scratch_itch.yaml"


@pytest.mark.slow
def test_sawyer_reaches_an_itch_on_the_front_of_the_upper_arm_and_scratches_it(tmp_path_factory):
    """Seed 17 draws the spot on the front of the upper arm (its normal towards -y, away from the
    robot's side). With the shared script Sawyer's tip ended 24 cm off, stuck under the elbow; its
    own script (out along the normal first, then in) reaches it and scratches 25 times."""
    from assistive_compiler.policies.scripted import ScriptedPolicy

    for env in compiled_env(tmp_path_factory, SCRATCH_ITCH, "sawyer"):
        policy = ScriptedPolicy(env)
        obs, _ = env.reset(seed=17)
        itch = policy.tracks[0].waypoints[0][0]
        normal = env.snap.normal(itch)
        assert int(np.argmax(np.abs(normal))) == 1 and normal[1] < 0  # the front (-y) of the arm
        done, info = False, {}
        while not done:
            obs, reward, terminated, truncated, info = env.step(policy(obs))
            done = terminated or truncated
        assert info["task_success"] == 1 and info["success_metric"] >= 25

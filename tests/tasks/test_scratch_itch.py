"""Scratch Itch's scripted baseline on a long arm: the tip goes round the limb to the spot."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import compiled_env

from assistive_compiler.paths import specs_dir

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


@pytest.mark.slow
def test_pr2_stands_in_front_of_the_person_and_scratches_the_back_of_the_upper_arm(tmp_path_factory):
    """PR2's base search keeps to the box in front of the person (robot.per_robot.pr2.base_search):
    from the whole box it kept a base beside the arm, whose start left the slow shoulder 1.4 rad
    from what seed 13's spot on the back of the upper arm (normal towards +y) needs, and the tip
    ended 22 cm off with 0 scratches. From the front it reaches the spot and scratches 25 times."""
    from assistive_compiler.policies.scripted import ScriptedPolicy

    for env in compiled_env(tmp_path_factory, SCRATCH_ITCH, "pr2"):
        for variant in env.manifest.person.variants:
            assert all(start.base_position[1] < -0.55 for start in variant.starts)  # in front of the arm (y ~0)
        policy = ScriptedPolicy(env)
        obs, _ = env.reset(seed=13)
        normal = env.snap.normal(policy.tracks[0].waypoints[0][0])
        assert int(np.argmax(np.abs(normal))) == 1 and normal[1] > 0  # the back (+y) of the arm
        done, info = False, {}
        while not done:
            obs, reward, terminated, truncated, info = env.step(policy(obs))
            done = terminated or truncated
        assert info["task_success"] == 1 and info["success_metric"] >= 25

"""Impairments are drawn at every reset with the paper's distributions, and the body obeys them."""

from __future__ import annotations

import math

import numpy as np
import pybullet as pb
import pytest

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.paths import specs_dir
from assistive_compiler.runtime.env import AssistiveEnv

FEEDING = specs_dir() / "tasks" / "feeding.yaml"
HEAD = ("neck", "head_x", "head_y", "head_z")

PAPER = """
person:
  impairments:
    choices:                      # the paper: one of these, uniformly, at every reset
      - {kind: none}
      - {kind: limited_range, joints: [person.head]}
      - {kind: weakness}
      - {kind: tremor}
"""


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("impairments")
    spec = tmp / "feeding_impaired.yaml"
    spec.write_text(f"extends: {FEEDING}\n" + PAPER)
    e = AssistiveEnv(compile_task(spec, "jaco", tmp / "out").out_dir)
    yield e
    e.close()


def head_angles(env) -> dict[str, float]:
    person = env.body_id("person")
    return {j: pb.getJointState(person, env.joint_index("person", j), physicsClientId=env.client)[0] for j in HEAD}


def test_draws_over_500_resets_follow_the_paper(env):
    kinds, amplitudes, strengths, scales = [], [], [], []
    for seed in range(500):
        impairment = env.reset(seed=seed)[1]["impairment"] if seed == 0 else env.reset()[1]["impairment"]
        kinds.append(impairment["kind"])
        amplitudes += list(impairment.get("amplitude", {}).values())
        strengths += [impairment["strength"]] if "strength" in impairment else []
        scales += [impairment["scale"]] if "scale" in impairment else []
    counts = {k: kinds.count(k) for k in ("none", "limited_range", "weakness", "tremor")}
    assert all(90 <= n <= 160 for n in counts.values()), counts  # 125 each expected
    assert set(kinds) == set(counts)
    eps = np.degrees(amplitudes)  # per-joint tremor ε ~ U(0°, 20°)
    assert eps.min() >= 0 and eps.max() <= 20 and abs(eps.mean() - 10) < 1.0
    assert min(strengths) >= 0.25 and max(strengths) <= 1 and abs(np.mean(strengths) - 0.625) < 0.04  # β ~ U(0.25, 1)
    assert min(scales) >= 0.5 and max(scales) <= 1 and abs(np.mean(scales) - 0.75) < 0.04  # γ ~ U(0.5, 1)


def test_limited_range_keeps_the_head_inside_the_scaled_limits(env):
    checked = 0
    for seed in range(300):
        info = env.reset(seed=seed)[1] if seed == 0 else env.reset()[1]
        if info["impairment"]["kind"] != "limited_range":
            continue
        limits = info["impairment"]["limits"]
        for _ in range(3):
            env.step(np.zeros(7, dtype=np.float32))
        for joint, q in head_angles(env).items():
            lo, hi = limits[joint]
            assert lo - 1e-3 <= q <= hi + 1e-3
        checked += 1
    assert checked > 40


def test_tremor_flips_sign_every_step(env):
    for seed in range(200):
        info = env.reset(seed=seed)[1]
        impairment = info["impairment"]
        if impairment["kind"] == "tremor" and max(impairment["amplitude"].values()) > math.radians(8):
            break
    else:
        pytest.fail("no tremor with a large amplitude drawn")
    joint = max(impairment["amplitude"], key=impairment["amplitude"].get)
    angles = [head_angles(env)[joint]]
    for _ in range(8):
        env.step(np.zeros(7, dtype=np.float32))
        angles.append(head_angles(env)[joint])
    # The held joint lags its target, but its motion turns round every step: +, −, +, − ...
    moves = np.sign(np.diff(angles))
    assert moves[0] > 0 and all(a == -b for a, b in zip(moves, moves[1:])), moves


def test_a_patient_card_fixes_the_impairment(tmp_path):
    spec = tmp_path / "card.yaml"
    spec.write_text(f"extends: {FEEDING}\nperson:\n  impairments:\n    choices: [{{kind: weakness, strength: 0.4}}]\n")
    env = AssistiveEnv(compile_task(spec, "jaco", tmp_path / "out").out_dir)
    try:
        for seed in range(5):
            assert env.reset(seed=seed)[1]["impairment"] == {
                "kind": "weakness",
                "joints": list(env.manifest.person.policy_joints),
                "strength": 0.4,
            }
    finally:
        env.close()


def test_a_compliant_arm_yields_where_a_held_one_does_not(tmp_path):
    """control.compliant holds the named joints weakly (the reference's reactive hold): pushed by
    the same external torque, the compliant arm moves and the stiffly held one barely does."""
    moved = {}
    for name, extra in (
        ("compliant", "    compliant: {joints: [person.right_arm], max_force_nm: 1.0, position_gain: 0.01}\n"),
        (
            "held",
            "  randomize_deg: {head_x: {uniform: [-30, 30]}, head_y: {uniform: [-30, 30]}, head_z: {uniform: [-30, 30]}, right_elbow: {uniform: [-90, -90]}}\n",
        ),
    ):
        spec = tmp_path / f"{name}.yaml"
        text = f"extends: {FEEDING}\nperson:\n"
        text += ("  control:\n" + extra) if name == "compliant" else extra
        spec.write_text(text)
        env = AssistiveEnv(compile_task(spec, "jaco", tmp_path / name).out_dir)
        env.reset(seed=0)
        person, c, elbow = env.body_id("person"), env.client, env.joint_index("person", "right_elbow")
        before = pb.getJointState(person, elbow, physicsClientId=c)[0]
        for _ in range(10):
            for _ in range(env.manifest.sim.frame_skip):
                pb.applyExternalTorque(
                    person, elbow, (20.0, 0, 0), pb.LINK_FRAME, physicsClientId=c
                )  # on the elbow joint's child link
                pb.stepSimulation(physicsClientId=c)
        moved[name] = abs(pb.getJointState(person, elbow, physicsClientId=c)[0] - before)
        env.close()
    assert moved["compliant"] > 0.1 and moved["held"] < 0.02, moved

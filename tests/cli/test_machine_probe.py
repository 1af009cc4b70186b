"""The machine probe that carries bench's stored reference figures over to the machine as it runs
now (issue 32), and the harness-episode measurement the ratio is taken on."""

from __future__ import annotations

import pytest

from assistive_compiler.cli.bench import (
    REFERENCE_PROBE_STEPS_PER_S,
    REFERENCE_STEPS_PER_S,
    measure_harness_protocol,
    reference_now,
)
from assistive_compiler.machine_probe import PROBE_VERSION, probe_fingerprint, probe_steps_per_s


def test_the_probe_workload_is_the_one_the_stored_figures_were_measured_with():
    """The stored reference figures are only comparable with the probe they were measured beside.
    If this fails, the workload changed: bump PROBE_VERSION, measure the reference figures and the
    probe again side by side, and store both (docs/physics.md, "What the ratio divides by")."""
    assert PROBE_VERSION == REFERENCE_PROBE_STEPS_PER_S[1] == 1
    hand, contacts = probe_fingerprint()
    assert hand == pytest.approx((0.5904, -0.1264, 0.8467), abs=2e-4)  # the arm swung out over the table
    assert contacts == 25  # the pile of six boxes on the table, and the held box on the hand
    assert probe_fingerprint() == (hand, contacts)  # the same work every run


def test_the_probe_measures_a_rate():
    assert probe_steps_per_s(steps=20, repeats=3) > 0


def test_stored_figures_are_carried_over_by_the_machine_speed():
    """A machine running at half the stored session's speed gets half the reference's figure; a
    figure from before the probe is not carried over; an unmeasured pair (the reference has no
    Stretch) gets none."""
    stored, how = REFERENCE_STEPS_PER_S[("arm_manipulation", "jaco")]
    probe_then = REFERENCE_PROBE_STEPS_PER_S[0]
    half = reference_now("arm_manipulation", "jaco", probe_then / 2)
    assert half is not None and half[:3] == (stored, 0.5, stored / 2)
    assert half[3].startswith("measured side by side on 2026-11-29") and half[3].endswith(
        "carried over to this machine's speed now by the machine probe (machine_speed_vs_reference_session)"
    )
    assert reference_now("arm_manipulation", "jaco", probe_then)[:3] == (stored, 1.0, stored)  # type: ignore[index]
    before_probe = reference_now("feeding", "sawyer", probe_then / 2)
    assert before_probe is not None and before_probe[:3] == (237, None, 237)
    assert "not carried over" in before_probe[3]
    assert reference_now("feeding", "stretch", probe_then) is None
    side_by_side = {pair for pair, (_, way) in REFERENCE_STEPS_PER_S.items() if way == how}
    assert side_by_side == {
        (task, robot)
        for task in ("feeding", "scratch_itch", "drinking", "bed_bathing", "arm_manipulation")
        for robot in ("jaco", "pr2")
    }


def test_harness_episodes_are_the_same_episodes_every_time(env):
    """The harness's protocol (reset seed 1001, ten resets, two episodes of rng(0) actions) replays
    the same episodes: the env ends in the same state both times."""
    import pybullet as pb

    def final_state():
        measure_harness_protocol(env)
        return pb.getLinkState(env.world.robot.id, env.arm_idx[-1], physicsClientId=env.client)[0]

    assert final_state() == final_state()

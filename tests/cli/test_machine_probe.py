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


def test_stored_figures_are_carried_over_by_the_machine_speed(monkeypatch):
    """A machine running at half the stored session's speed gets half the reference's figure; with
    a probe of another version the figure is not carried over, and says to measure it again; an
    unmeasured pair (the reference has no Stretch) gets none."""
    from assistive_compiler.cli import bench

    stored = REFERENCE_STEPS_PER_S[("arm_manipulation", "jaco")]
    probe_then = REFERENCE_PROBE_STEPS_PER_S[0]
    half = reference_now("arm_manipulation", "jaco", probe_then / 2)
    assert half is not None and half[:3] == (stored, 0.5, stored / 2)
    assert half[3].startswith("measured side by side on 2026-11-29") and half[3].endswith(
        "carried over to this machine's speed now by the machine probe (machine_speed_vs_reference_session)"
    )
    assert reference_now("arm_manipulation", "jaco", probe_then)[:3] == (stored, 1.0, stored)  # type: ignore[index]
    assert reference_now("feeding", "stretch", probe_then) is None
    assert set(REFERENCE_STEPS_PER_S) == {
        (task, robot)
        for task in ("feeding", "scratch_itch", "drinking", "bed_bathing", "arm_manipulation")
        for robot in ("jaco", "pr2", "baxter", "sawyer")
    }
    monkeypatch.setattr(bench, "REFERENCE_PROBE_STEPS_PER_S", (probe_then, PROBE_VERSION + 1))
    other = reference_now("arm_manipulation", "jaco", probe_then / 2)
    assert other is not None and other[:3] == (stored, None, stored)
    assert "not carried over" in other[3] and "benchmarks/reference_side_by_side.py" in other[3]


def test_harness_episodes_are_the_same_episodes_every_time(env):
    """The harness's protocol (reset seed 1001, ten resets, two episodes of rng(0) actions) replays
    the same episodes: the env ends in the same state both times."""
    import pybullet as pb

    def final_state():
        measure_harness_protocol(env)
        return pb.getLinkState(env.world.robot.id, env.arm_idx[-1], physicsClientId=env.client)[0]

    assert final_state() == final_state()


def _side_by_side_script():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "benchmarks" / "reference_side_by_side.py"
    spec = importlib.util.spec_from_file_location("reference_side_by_side", path)
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def test_the_side_by_side_script_summarizes_into_the_stored_figures():
    """benchmarks/reference_side_by_side.py turns the harness's lines and the probe's into the figures
    bench stores: the reference on its fork (its gravity emulation's share removed), medians over
    rounds; an env measured on our side only (the reference failed to load it) is left out."""
    script = _side_by_side_script()
    lines = [
        {"side": "ag", "env": "ArmManipulationPR2", "steps_per_s": 60.0, "gravity_shim_share": 0.5},
        {"side": "ag", "env": "ArmManipulationPR2", "steps_per_s": 66.0, "gravity_shim_share": 0.5},
        {"side": "ag", "env": "ArmManipulationPR2", "steps_per_s": 70.0, "gravity_shim_share": 0.5},
        {"side": "ours", "env": "ArmManipulationPR2", "steps_per_s": 400.0},
        {"side": "ours", "env": "ArmManipulationPR2", "steps_per_s": 420.0},
        {"side": "ours", "env": "ArmManipulationPR2", "steps_per_s": 390.0},
        {"side": "ours", "env": "FeedingBaxter", "steps_per_s": 460.0},
        {"side": "probe", "probe_version": 1, "steps_per_s": 1700.0},
        {"side": "probe", "probe_version": 1, "steps_per_s": 1800.0},
    ]
    summary = script.summarize(lines)
    assert summary["envs"] == {"ArmManipulationPR2": {"reference": 132.0, "ours": 400.0, "ratio": 3.03, "rounds": 3}}
    assert summary["probe_steps_per_s"] == 1750.0 and summary["probe_versions"] == [1]
    assert script.stored_lines(summary) == [
        '    ("arm_manipulation", "pr2"): 132.0,',
        "REFERENCE_PROBE_STEPS_PER_S = (1750.0, 1)",
    ]
    assert script.task_robot("BedBathingSawyer") == ("bed_bathing", "sawyer")
    assert script.task_robot("DressingJaco") is None  # not one of the five rigid tasks

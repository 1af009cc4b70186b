"""The reference implementation's solver settings and the spec variant that uses them (issue 17)."""

from __future__ import annotations

from pathlib import Path

import pybullet as pb
import pytest

from assistive_compiler.spec.load import load_spec
from assistive_compiler.spec.reference_solver import (
    PYBULLET_DEFAULT_SOLVER,
    REFERENCE_SOLVER,
    reference_solver,
    solver_settings,
    write_reference_variant,
)

TASKS = Path(__file__).resolve().parents[2] / "specs" / "tasks"


def test_pybullet_defaults_are_what_the_reference_runs_at():
    """The reference keeps PyBullet's defaults unless a task overrides them: 0 sub-steps, 50 iterations."""
    c = pb.connect(pb.DIRECT)
    try:
        params = pb.getPhysicsEngineParameters(physicsClientId=c)
    finally:
        pb.disconnect(c)
    assert params["numSubSteps"] == PYBULLET_DEFAULT_SOLVER["sub_steps"] == 0
    assert params["numSolverIterations"] == PYBULLET_DEFAULT_SOLVER["iterations"] == 50


def test_every_shipped_task_has_reference_settings():
    assert {p.stem for p in TASKS.glob("*.yaml")} == set(REFERENCE_SOLVER)
    assert reference_solver("drinking") == {"sub_steps": 4, "iterations": 10, "contact_breaking_threshold_m": 0.02}
    assert reference_solver("dressing") == {"sub_steps": 8, "iterations": 50, "contact_breaking_threshold_m": 0.02}
    assert reference_solver("no_such_task") is None


@pytest.mark.parametrize("task", sorted(REFERENCE_SOLVER))
def test_the_variant_differs_from_the_shipped_spec_in_sim_solver_only(task, tmp_path):
    spec_path = TASKS / f"{task}.yaml"
    shipped = load_spec(spec_path)
    variant = write_reference_variant(spec_path, shipped.spec, tmp_path)
    if solver_settings(shipped.spec) == reference_solver(task):
        assert variant is None  # nothing to compare: bench reports the one figure for both
        return
    loaded = load_spec(variant)
    assert solver_settings(loaded.spec) == reference_solver(task)
    assert loaded.files[1] == spec_path.resolve()
    other = dict(loaded.data, sim={k: v for k, v in loaded.data["sim"].items() if k != "solver"})
    ours = dict(shipped.data, sim={k: v for k, v in shipped.data["sim"].items() if k != "solver"})
    assert other == ours

"""The reference implementation's solver settings per task, and a spec variant that uses them.

Assistive Gym v1.0 keeps PyBullet's defaults (``numSubSteps`` 0, ``numSolverIterations`` 50,
contact breaking threshold 0.02 m: ``pybullet.getPhysicsEngineParameters()`` on stock 3.2.7)
unless a task overrides them: Drinking sets 4 sub-steps and 10 iterations, Dressing 8 sub-steps
(Feeding's override is commented out). ``bench`` measures a task at these settings beside the
shipped ones, and ``benchmarks/physics_settings.py`` compares the outcomes of the two
(docs/physics.md).

The variant is a spec file that ``extends:`` the shipped one and overrides ``sim.solver`` only,
so it compiles like any user spec (the person's compile-time settle runs at its settings too).
"""

from __future__ import annotations

from pathlib import Path

from .models import TaskSpec

PYBULLET_DEFAULT_SOLVER = {"sub_steps": 0, "iterations": 50, "contact_breaking_threshold_m": 0.02}
"""PyBullet's defaults (numSubSteps, numSolverIterations, contact breaking threshold in m)."""

REFERENCE_SOLVER: dict[str, dict] = {
    "scratch_itch": PYBULLET_DEFAULT_SOLVER,
    "bed_bathing": PYBULLET_DEFAULT_SOLVER,
    "feeding": PYBULLET_DEFAULT_SOLVER,
    "arm_manipulation": PYBULLET_DEFAULT_SOLVER,
    "drinking": {**PYBULLET_DEFAULT_SOLVER, "sub_steps": 4, "iterations": 10},
    "dressing": {**PYBULLET_DEFAULT_SOLVER, "sub_steps": 8},
}
"""The reference's ``sim.solver`` per task name (the reference implementation, Assistive Gym v1.0: PyBullet's defaults unless a task overrides them)."""


def solver_settings(spec: TaskSpec) -> dict:
    """The spec's ``sim.solver`` as a plain dict (the keys of :data:`PYBULLET_DEFAULT_SOLVER`)."""
    s = spec.sim.solver
    return {
        "sub_steps": s.sub_steps,
        "iterations": s.iterations,
        "contact_breaking_threshold_m": s.contact_breaking_threshold_m,
    }


def reference_solver(task: str) -> dict | None:
    """The reference's solver settings for a task name; None for a task the reference does not have."""
    return REFERENCE_SOLVER.get(task)


def write_solver_variant(spec_path: str | Path, solver: dict, out: str | Path) -> Path:
    """Write the spec file ``out``: the spec at ``spec_path`` with ``sim.solver`` overridden by ``solver``."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    settings = ", ".join(f"{k}: {v}" for k, v in solver.items())
    out.write_text(
        f"# {Path(spec_path).name} with other solver settings (spec/reference_solver.py)\n"
        f"extends: {Path(spec_path).resolve()}\nsim:\n  solver: {{{settings}}}\n"
    )
    return out


def write_reference_variant(spec_path: str | Path, spec: TaskSpec, out_dir: str | Path) -> Path | None:
    """Write ``<out_dir>/<task>_reference_solver.yaml``: the spec at ``spec_path`` with the reference's
    ``sim.solver``. None when the task has no reference settings or already uses them."""
    ref = reference_solver(spec.name)
    if ref is None or ref == solver_settings(spec):
        return None
    return write_solver_variant(spec_path, ref, Path(out_dir) / f"{spec.name}_reference_solver.yaml")

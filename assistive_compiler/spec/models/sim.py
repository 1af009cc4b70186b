"""``sim``: time step, frame skip, episode length, gravity, solver settings and the floor."""

from __future__ import annotations

from pydantic import Field, field_validator

from .common import Scalar, Strict, Uniform, scalar_bounds


class Solver(Strict):
    """Bullet constraint-solver settings (``setPhysicsEngineParameter``). The defaults are PyBullet's,
    which the reference keeps unless a task overrides them; docs/physics.md shows what fewer
    iterations or sub-steps change."""

    sub_steps: int = Field(0, ge=0, le=64, description="numSubSteps: extra sub-steps per physics step (0 = none).")
    iterations: int = Field(50, ge=1, le=1000, description="numSolverIterations per physics step.")
    contact_breaking_threshold_m: float = Field(
        0.02,
        gt=0,
        le=0.1,
        description="Distance (m) a cached contact point may drift before Bullet drops it (Bullet's default 0.02). "
        "Small rolling particles pile up stale copies of their one contact under the default, each a "
        "solver row: 0.002 cuts Feeding's physics by 14% and Drinking's by 21%, but changes how deep "
        "particles sink, and stale points widen where a contact is reported (Bed Bathing's wiping counts "
        "them); the shipped tasks keep the default, as the reference does (docs/physics.md).",
    )


class Ground(Strict):
    """The floor (its top face at z = 0)."""

    friction: Scalar = Field(
        default_factory=lambda: Uniform(uniform=(0.025, 0.5)),
        description="Lateral friction coefficient of the floor (the reference re-draws U(0.025, 0.5) every reset).",
    )

    @field_validator("friction")
    @classmethod
    def _nonnegative(cls, v: Scalar) -> Scalar:
        if scalar_bounds(v)[0] < 0:
            raise ValueError("friction must be ≥ 0")
        return v


class Sim(Strict):
    """Timing and world physics. The paper: 0.02 s physics steps, 5 per action (10 Hz), 200 actions."""

    time_step_s: float = Field(0.02, gt=0, le=0.1, description="Physics time step in seconds.")
    frame_skip: int = Field(5, ge=1, le=100, description="Physics steps per environment step (action).")
    episode_steps: int = Field(200, ge=1, le=100_000, description="Environment steps per episode (then truncated).")
    gravity_mps2: float = Field(
        -9.81, ge=-20, le=0, description="World gravity along +Z in m/s² (negative: downwards)."
    )
    solver: Solver = Field(default_factory=Solver, description="Constraint-solver settings.")
    ground: Ground = Field(default_factory=Ground, description="The floor.")

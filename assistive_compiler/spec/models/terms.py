"""``observations``, ``reward``, ``preferences`` and ``success``: the term uses of a task."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, model_validator

from .common import Name, Strict


class TermUse(Strict):
    """Use of a registered term: its kind, parameters (checked against the term's schema) and weight."""

    term: Name = Field(description="Registered term kind (see `assistive-compiler schema --terms`).")
    params: dict[str, Any] = Field(default_factory=dict, description="The term's parameters.")


class RewardTerm(TermUse):
    """One weighted reward term. The step reward is Σ weight·value; info reports every value."""

    name: Name = Field(description="Name of this term in info and logs.")
    weight: float = Field(description="Multiplier of the term's value (negative to penalise).")
    arms: Literal[1, 2] | None = Field(
        None,
        description="Only for robots acting with this many arms (2: a two-arm robot in a task with arm 'both'); "
        "None: every robot. E.g. the reference's single-arm arm manipulation doubles a distance term.",
    )


class Observations(Strict):
    """Observation vectors per agent: features concatenated in order into one float32 Box."""

    robot: list[TermUse] = Field(min_length=1, description="The robot's observation features, in order.")
    human: list[TermUse] = Field(default_factory=list, description="The person's (co-optimisation) features.")


PREFERENCE_NAMES = (
    "velocity",
    "force_nontarget",
    "high_force",
    "food_hit",
    "food_velocity",
    "dressing_force",
    "pressure",
)
"""The paper's seven preference costs C_v, C_f, C_hf, C_fd, C_fdv, C_d, C_p, in its order."""

PAPER_PREFERENCE_WEIGHTS = dict(zip(PREFERENCE_NAMES, (0.25, 0.01, 0.05, 1.0, 1.0, 0.01, 0.01)))


class Preference(Strict):
    """One active preference cost: its inputs and, optionally, a weight other than the paper's."""

    weight: float | None = Field(None, ge=0, description="ω for this cost (None: the paper's value).")
    params: dict[str, Any] = Field(default_factory=dict, description="The cost's inputs (which link, which forces).")


class Preferences(Strict):
    """The human-preference reward r_H = Σ ω_k·c_k over the costs active for this task (α_k = 1)."""

    active: dict[Name, Preference] = Field(
        default_factory=dict, description=f"Active costs by name; names are {', '.join(PREFERENCE_NAMES)}."
    )


class Success(Strict):
    """Task success: an aggregate of one reward term's value over the episode against a threshold."""

    term: Name = Field(description="Name of a reward term whose value is aggregated.")
    aggregate: Literal["sum", "max", "min", "last"] = Field(description="How the per-step values are combined.")
    threshold: float = Field(description="Success when aggregate ≥ threshold.")
    relative_to: Name | None = Field(
        None, description="A particle or marker set: the threshold is then a fraction (0, 1] of its count."
    )

    @model_validator(mode="after")
    def _fraction(self) -> Success:
        if self.relative_to is not None and not (0 < self.threshold <= 1):
            raise ValueError(
                f"@threshold: threshold {self.threshold:g} is a fraction of '{self.relative_to}' and must lie in (0, 1]"
            )
        return self

"""Shared building blocks of the spec models: names, references, vectors, colours, the strict base
model and random quantities (a number, or ``{uniform: [lo, hi]}`` drawn per reset)."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field, model_validator

Name = Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*$", max_length=64)]
Ref = Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*(\.[a-z][a-z0-9_]*)?$", max_length=129)]
Vec3 = tuple[float, float, float]
Rgba = tuple[
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
]


class Strict(BaseModel):
    """Base of every spec model: unknown keys are errors, NaN and infinities are refused."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True, populate_by_name=False)


# --------------------------------------------------------------------------------------------
# Random quantities


class Uniform(Strict):
    """A value drawn uniformly from [low, high] at every reset."""

    uniform: tuple[float, float] = Field(description="Bounds [low, high] of a uniform draw; low ≤ high.")

    @model_validator(mode="after")
    def _ordered(self) -> Uniform:
        low, high = self.uniform
        if low > high:
            raise ValueError(f"@uniform: bounds are reversed: low {low:g} > high {high:g}; write [low, high]")
        return self


Scalar = float | Uniform
"""A fixed number or ``{uniform: [low, high]}`` re-drawn at every reset."""


def describe(value: Scalar) -> str:
    """``1.5`` or ``U(0.2, 0.9)`` for messages."""
    low, high = scalar_bounds(value)
    return f"{low:g}" if low == high else f"U({low:g}, {high:g})"


def scalar_bounds(value: Scalar) -> tuple[float, float]:
    """The smallest and largest value a :data:`Scalar` can take."""
    if isinstance(value, Uniform):
        return value.uniform
    return (float(value), float(value))

"""An episode's impairment of the person, drawn from the task's choices (paper §III-C): tremor
ε per joint (rad), weakness β (a factor on the joints' forces) or limited range γ (a factor on
each joint's limits, rad). :class:`~.human.PersonController` applies it; the reset's
:class:`~.component.Episode` carries it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..artifact import Impairment, LimitedRange, Tremor, Weakness


@dataclass(frozen=True)
class DrawnImpairment:
    """An episode's impairment with its drawn values (paper §III-C)."""

    kind: str
    """'none', 'tremor', 'weakness' or 'limited_range'."""
    joints: tuple[str, ...] = ()
    """The person joints it acts on."""
    amplitude: dict[str, float] = field(default_factory=dict)
    """Tremor: ε per joint, rad."""
    strength: float = 1.0
    """Weakness: β, the factor on the joints' forces."""
    scale: float | None = None
    """Limited range: γ."""
    limits: dict[str, tuple[float, float]] = field(default_factory=dict)
    """Limited range: each joint's limits × γ, rad."""

    def info(self) -> dict[str, Any]:
        """As ``reset()``'s ``info["impairment"]`` reports it: kind, joints and the drawn values."""
        out: dict[str, Any] = {"kind": self.kind, "joints": list(self.joints)}
        if self.kind == "tremor":
            out["amplitude"] = dict(self.amplitude)
        elif self.kind == "weakness":
            out["strength"] = self.strength
        elif self.kind == "limited_range":
            out["scale"], out["limits"] = self.scale, dict(self.limits)
        return out


def draw_impairment(choices: list[Impairment], rng: np.random.Generator) -> DrawnImpairment:
    """One impairment for an episode, drawn uniformly from the task's choices, with its values:
    tremor ε per joint (rad), weakness β, or limited range γ (each joint's limits × γ, as the
    paper scales them)."""
    choice = choices[int(rng.integers(len(choices)))]
    joints = tuple(choice.joints)
    if isinstance(choice, Tremor):
        lo, hi = choice.amplitude_rad
        return DrawnImpairment("tremor", joints, amplitude={j: float(rng.uniform(lo, hi)) for j in joints})
    if isinstance(choice, Weakness):
        return DrawnImpairment("weakness", joints, strength=float(rng.uniform(*choice.strength)))
    if isinstance(choice, LimitedRange):
        gamma = float(rng.uniform(*choice.scale))
        limits = {j: (lo * gamma, hi * gamma) for j, (lo, hi) in choice.limits.items()}
        return DrawnImpairment("limited_range", joints, scale=gamma, limits=limits)
    return DrawnImpairment(choice.kind, joints)

"""What lives through an episode: the :class:`Episode` a reset fills in, the :class:`EnvStep`
being taken, and the one protocol of the env's components.

A component — the person (:mod:`.human`), markers (:mod:`.markers`), particles (:mod:`.particles`),
garments and the reward terms with memory (:mod:`.events`) — is started by its ``reset`` event
(the manifest orders them among the draws, :mod:`.events`), then each env step gets
:meth:`EpisodeComponent.before_physics` before the physics runs and
:meth:`EpisodeComponent.after_step` after it and after the snapshot's refresh, both in the env's
component order (person, particles, markers, garments, reward terms).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ..artifact import PersonVariant
    from .impairment import DrawnImpairment


@dataclass
class Episode:
    """One reset's draws, filled in by its events in order, from one random stream."""

    rng: np.random.Generator
    """The env's ``np_random``: every draw of the reset comes from it, in event order."""
    options: Mapping[str, Any] = field(default_factory=dict)
    """``reset(options=...)``: ``person_variant`` chooses the person body by name."""
    variant: PersonVariant | None = None
    """The person body of the episode (the ``person_variant`` event)."""
    start_index: int | None = None
    """Which of the variant's precomputed robot starts (the ``robot_start`` event)."""
    impairment: DrawnImpairment | None = None
    """The person's impairment with its drawn values (the person's reset)."""

    def info(self) -> dict[str, Any]:
        """``reset()``'s info: ``person_variant`` (name), ``start`` (index), ``impairment``."""
        assert self.variant is not None and self.impairment is not None, "a reset without a person"
        return {"person_variant": self.variant.name, "start": self.start_index, "impairment": self.impairment.info()}


@dataclass(frozen=True)
class EnvStep:
    """The env step about to run."""

    index: int
    """Env steps already taken this episode (0 on the first)."""
    human_action: np.ndarray | None
    """The person's action in ``human_action_space`` (co-optimisation), or None: it holds."""


class EpisodeComponent:
    """A part of the env with per-episode state. Each method is a no-op unless overridden."""

    def reset(self, episode: Episode) -> None:
        """Start an episode (the component's ``reset`` event; draws come from ``episode.rng``)."""

    def before_physics(self, step: EnvStep) -> None:
        """Before the physics of an env step (motor commands, releasing particles, ...)."""

    def after_step(self) -> None:
        """After the physics and the snapshot's refresh (clearing markers, catching particles, ...)."""

"""The built-in terms by category: the registry (:mod:`.registry`) once every term module
(:mod:`.rewards`, :mod:`.observations`, :mod:`.preferences`) has registered its terms.

The term modules import the registry to register themselves; this module imports them, and the
registry imports neither, so the registry and its terms form no import circle.
"""

from __future__ import annotations

from . import observations, preferences, rewards  # noqa: F401  (registration side effects)
from .registry import REGISTRY, Category, TermDef


def terms(category: Category) -> dict[str, TermDef]:
    """All registered terms of ``category``: the built-in ones and any a user module registered."""
    return REGISTRY[category]

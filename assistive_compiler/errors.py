"""User-facing errors: every problem in a spec is reported as ``PATH:LINE:COL: message``.

A :class:`Problem` is one located message. :class:`SpecError` carries one or more problems and is
the only exception the loading, resolving and compiling stages raise for bad *input*; the CLI
prints its problems one per line and exits 2. Anything else escaping those stages is a bug.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True, order=True)
class Location:
    """A place in a source file. ``line`` and ``column`` are 1-based, as editors show them."""

    path: str
    line: int = 1
    column: int = 1

    def __str__(self) -> str:
        return f"{self.path}:{self.line}:{self.column}"


@dataclass(frozen=True)
class Problem:
    """One located message about user input."""

    location: Location
    message: str

    def __str__(self) -> str:
        return f"{self.location}: {self.message}"


class SpecError(Exception):
    """One or more problems with user input (a spec, a part, a template parameter)."""

    def __init__(self, problems: Sequence[Problem]):
        self.problems = sorted(problems, key=lambda p: (p.location, p.message))
        super().__init__("\n".join(str(p) for p in self.problems))

    @classmethod
    def at(cls, path: str | Path, message: str, line: int = 1, column: int = 1) -> SpecError:
        return cls([Problem(Location(str(path), line, column), message)])

    def __reduce__(self):
        # Rebuilt from its problems (not from the joined message Exception would pickle), so a
        # SpecError raised in a worker process (a Ray env runner) arrives with its locations intact.
        return (type(self), (self.problems,))


class UsageError(Exception):
    """Bad command-line input that is not in a file (an unknown engine, an unreachable cluster);
    the CLI prints ``error: message`` and exits 2."""


def suggest(word: str, choices: Iterable[str]) -> str | None:
    """The closest of ``choices`` to a misspelled ``word``, or None when nothing is close."""
    choices = list(choices)
    matches = difflib.get_close_matches(word, choices, n=1, cutoff=0.6)
    if not matches:
        lowered = {c.lower(): c for c in choices}
        matches = [lowered[m] for m in difflib.get_close_matches(word.lower(), lowered, n=1, cutoff=0.6)]
    return matches[0] if matches else None


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` when a close match exists, else an empty string."""
    match = suggest(word, choices)
    return f" (did you mean '{match}'?)" if match else ""


def one_of(choices: Iterable[str], limit: int = 12) -> str:
    """A readable list of the valid choices for an error message."""
    choices = sorted(choices)
    shown = ", ".join(f"'{c}'" for c in choices[:limit])
    if len(choices) > limit:
        shown += f", ... ({len(choices)} in all)"
    return shown

"""Located problems: the one collector every resolution pass reports into.

A pass names the place of a mistake by its path in the spec (e.g. ``("tools", "spoon", "part")``);
the collector turns the path into the file, line and column where that value (or its key) was
written, and keeps the message. Resolution raises one :class:`SpecError` with every problem it
found, so a user sees all the mistakes of a spec at once.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from ..errors import Location, Problem, SpecError, did_you_mean, one_of
from ..spec.load import LoadedSpec
from ..spec.validation import inherited_note


class Collector:
    """Problems about one loaded spec, each located at a path of the spec."""

    def __init__(self, loaded: LoadedSpec):
        self.loaded = loaded
        self.problems: list[Problem] = []

    def at(self, *path: Any) -> Location:
        """Where the value at ``path`` was written."""
        return self.loaded.smap.value(tuple(path))

    def key_at(self, *path: Any) -> Location:
        """Where the key of ``path``'s last step was written (for a name that is itself wrong)."""
        return self.loaded.smap.key(tuple(path))

    def problem(self, path: tuple, message: str, key: bool = False) -> None:
        """Report ``message`` at ``path`` (once: a segment's waypoint is checked wherever it is spliced in)."""
        where = self.key_at(*path) if key else self.at(*path)
        problem = Problem(where, message + inherited_note(self.loaded.smap, where, tuple(path)))
        if problem not in self.problems:
            self.problems.append(problem)

    def fail_if_any(self) -> None:
        """Raise every problem collected so far, if there is one."""
        if self.problems:
            raise SpecError(self.problems)


def expected(pool: Iterable[str], word: str, *, limit: int = 12, empty: str = "") -> str:
    """The tail of every unknown-name message: ``expected one of 'a', 'b' (did you mean 'a'?)``;
    ``empty`` stands in for the list when ``pool`` is empty."""
    pool = list(pool)
    return f"expected one of {one_of(pool, limit) or empty}{did_you_mean(word, pool)}"

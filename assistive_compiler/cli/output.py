"""How the CLI shows results: tables on stdout and progress on stderr, both drawn by ``rich``.

Tables (:func:`print_table`) go to stdout with columns sized to their contents (never wrapped or
cut when stdout is a file or a pipe); numbers right-aligned. Progress (:func:`progress`) goes to
stderr, so ``--json`` output on stdout stays pure JSON: a live bar when stderr is a terminal, and
in every case one line per finished item saying what finished. Only the CLI imports this module
(``import assistive_compiler`` never imports rich).
"""

from __future__ import annotations

import sys
from collections.abc import Collection, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from rich import box
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn
from rich.table import Table
from rich.text import Text

MISSING = "-"
"""What a table shows for a value that does not apply (None or absent)."""


def cell(value: Any, digits: int | None = None) -> str:
    """A value as a table shows it: None as ``-``, floats to ``digits`` decimals when given."""
    if value is None:
        return MISSING
    if digits is not None and isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def _print(renderable: Any) -> None:
    """Print to stdout (looked up at call time: tests capture it). On a terminal, rich draws it
    (with bold headers); elsewhere it is laid out as wide as its contents (rich would otherwise
    fold it to 80 columns) and printed as plain lines without trailing blanks."""
    out = sys.stdout
    if out.isatty():
        Console(file=out, highlight=False).print(renderable)
        return
    console = Console(file=out, width=100_000, highlight=False, color_system=None)
    with console.capture() as captured:
        console.print(renderable)
    print("\n".join(line.rstrip() for line in captured.get().splitlines()))


def print_table(
    columns: Sequence[str],
    rows: Sequence[Sequence[str]],
    *,
    left: Sequence[str] = (),
    title: str | None = None,
    caption: str | None = None,
    section_after: Collection[int] = (),
) -> None:
    """Print ``rows`` (cells as strings, see :func:`cell`) under ``columns``; the ``left`` columns
    are left-aligned (text), the others right-aligned (numbers). ``caption`` explains the table
    below it; a rule follows the rows whose indices are in ``section_after``."""
    table = Table(
        box=box.SIMPLE_HEAD,
        show_edge=False,
        pad_edge=False,
        header_style="bold",
        title=title,
        title_justify="left",
        caption=caption,
        caption_justify="left",
    )
    for name in columns:
        table.add_column(name, justify="left" if name in left else "right")
    for i, row in enumerate(rows):
        table.add_row(*(Text(c) for c in row), end_section=i in section_after)  # Text: "[1, 2]" is no markup
    _print(table)


class Tracker:
    """Reports finished items of a long command (see :func:`progress`)."""

    def __init__(self, total: int, bar: Progress | None, task: Any, enabled: bool):
        self.total, self.count = total, 0
        self._bar, self._task, self._enabled = bar, task, enabled

    def done(self, message: str) -> None:
        """One item finished: ``message`` says which and how it went."""
        self.count += 1
        if not self._enabled:
            return
        line = f"[{self.count}/{self.total}] {message}"
        if self._bar is not None:
            self._bar.console.print(Text(line))
            self._bar.advance(self._task)
        else:
            print(line, file=sys.stderr, flush=True)


@contextmanager
def progress(description: str, total: int, *, enabled: bool = True) -> Iterator[Tracker]:
    """Progress of ``total`` items on stderr: a rich bar on a terminal, plain lines elsewhere."""
    if not (enabled and sys.stderr.isatty()):
        yield Tracker(total, None, None, enabled)
        return
    console = Console(file=sys.stderr, highlight=False)
    columns = (
        SpinnerColumn(),
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
    )
    with Progress(*columns, console=console, transient=True) as bar:
        yield Tracker(total, bar, bar.add_task(description, total=total), enabled)

"""Reading and showing the lint's numbers: a URDF attribute's finite floats, a number as the user
wrote it or as the linter computed it (6 significant digits), a vector, a count with its noun."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET


def fmt(value: float) -> str:
    """A number the user wrote, shown exactly (``-1.0``, ``0.3``, ``1e-05``)."""
    return repr(float(value))


def fmt_derived(value: float) -> str:
    """A number the linter computed (eigenvalues, lengths), shown to 6 significant digits."""
    text = f"{float(value):.6g}"
    return "0" if text == "-0" else text


def vec(values: tuple[float, ...] | list[float], derived: bool = False) -> str:
    show = fmt_derived if derived else fmt
    return "(" + ", ".join(show(v) for v in values) + ")"


def parse_numbers(text: str | None, count: int) -> tuple[float, ...] | None:
    """``count`` finite floats from a whitespace-separated attribute, else None."""
    if text is None:
        return None
    parts = text.split()
    if len(parts) != count:
        return None
    try:
        values = tuple(float(part) for part in parts)
    except ValueError:
        return None
    if not all(math.isfinite(v) for v in values):
        return None
    return values


def number(elem: ET.Element, attr: str) -> float | None:
    values = parse_numbers(elem.get(attr), 1)
    return None if values is None else values[0]


def plural(count: int, word: str) -> str:
    return f"{count} {word}" if count == 1 else f"{count} {word}s"

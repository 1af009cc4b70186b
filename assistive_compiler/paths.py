"""Where the shipped specs and templates live: the repository root in a checkout, or inside the
installed package (the wheel carries ``specs/`` and ``templates/`` as package data)."""

from __future__ import annotations

from functools import cache
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


@cache
def data_root() -> Path:
    """The directory holding ``specs/`` and ``templates/``."""
    for candidate in (_PACKAGE.parent, _PACKAGE / "_data"):
        if (candidate / "specs").is_dir() and (candidate / "templates").is_dir():
            return candidate
    raise RuntimeError(f"assistive_compiler data (specs/, templates/) not found near {_PACKAGE}")


def specs_dir() -> Path:
    return data_root() / "specs"


def templates_dir() -> Path:
    return data_root() / "templates"


def display(path: Path) -> str:
    """A path as shown in messages: relative to the working directory when it is inside it."""
    path = Path(path)
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)

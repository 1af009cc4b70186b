"""The command line of a record stored in ``tests/data`` (``python -m tests.<record> [--write]
[NAMES...]``): play each name on the current code, say per name whether it matches the record (or
where it first differs), and with ``--write`` store what was played. Exit status 1 when something
differs and nothing was written."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any


def compare_or_write(
    store: Path,
    description: str,
    names_help: str,
    default_names: Callable[[], Iterable[str]],
    play: Callable[[str], Any],
    difference: Callable[[Any, Any], str | None],
    argv: list[str] | None = None,
    instead_of_playing: tuple[str, str, Callable[[str], Any]] | None = None,
) -> int:
    """Compare ``play(name)`` with ``store``'s entry for each name (``difference(stored, played)``:
    None when they match, else where they differ), or write them with ``--write``.
    ``instead_of_playing``: (flag, help, outcomes) — with that flag, ``outcomes(name)`` stands for
    playing (e.g. episodes already played on the current code and recorded elsewhere)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--write", action="store_true", help=f"write {store.name} (else compare with it)")
    if instead_of_playing:
        parser.add_argument(instead_of_playing[0], action="store_true", dest="instead", help=instead_of_playing[1])
    parser.add_argument("names", nargs="*", help=names_help)
    args = parser.parse_args(argv)
    if instead_of_playing and args.instead:
        play = instead_of_playing[2]
    stored = json.loads(store.read_text()) if store.is_file() else {}
    changed = 0
    for name in args.names or default_names():
        played = play(name)
        where = difference(stored[name], played) if name in stored else "not stored"
        print(f"{name}: {where or 'same'}", flush=True)
        changed += where is not None
        stored[name] = played
    if args.write:
        store.write_text(json.dumps(dict(sorted(stored.items())), indent=1) + "\n")
        print(f"wrote {store}")
    return 1 if changed and not args.write else 0

"""``assistive-compiler`` — validate, compile, inspect and run task specs.

Exit status: 0 success, 2 bad input (problems printed one per line as ``PATH:LINE:COL: message``),
1 a run that failed for another stated reason. Heavy modules are imported by the command that
needs them, so ``validate`` and ``schema`` start fast.

One module per command group, each exposing ``add_commands(sub)``: it adds its subcommands to
the argparse subparsers ``sub`` and points each at its handler with ``set_defaults(func=...)``
(a handler takes the parsed arguments and returns the exit status). :data:`COMMAND_MODULES` lists
them in the order ``--help`` shows them; a new command (train, evaluate, view, ...) is a new
module added to that list. The work a command does lives in plain functions beside its handler
(``run.rollout``, ``bench.bench`` and its ``measure_*``, ``compare.compare_robot``), so other
commands reuse them; tables and progress come from :mod:`.output` (rich), which only the CLI
imports.

* :mod:`.spec_commands` — validate, compile, schema, list
* :mod:`.run` — run, demo
* :mod:`.render` — render, render-person
* :mod:`.bench` — bench
* :mod:`.compare` — compare
* :mod:`.train`, :mod:`.evaluate`, :mod:`.table` — learning (the optional ``train`` extra)
* :mod:`.view` — view (browser or pybullet GUI)
* :mod:`.collect` — collect (Minari datasets)
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence

from ..errors import SpecError, UsageError
from . import bench, collect, compare, describe, evaluate, render, results, run, spec_commands, table, train, view
from .common import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, print_problems, spec_from_gym_id, use_library_dirs

COMMAND_MODULES = (spec_commands, run, render, describe, bench, compare, view, collect, train, evaluate, table, results)

__all__ = ["COMMAND_MODULES", "EXIT_BAD_INPUT", "EXIT_FAILED", "EXIT_OK", "build_parser", "main"]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="assistive-compiler", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module in COMMAND_MODULES:
        module.add_commands(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        use_library_dirs(getattr(args, "library", []))
        spec_from_gym_id(args)
        return func(args)
    except SpecError as exc:
        print_problems(exc)
        return EXIT_BAD_INPUT
    except UsageError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): not an error. Point stdout at /dev/null so the
        # interpreter's final flush does not raise again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK

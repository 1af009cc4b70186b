"""``assistive-compiler`` — validate, compile, inspect and run task specs.

Exit status: 0 success, 2 bad input (problems printed one per line as ``PATH:LINE:COL: message``),
1 a run that failed for another stated reason. Heavy modules are imported by the command that
needs them, so ``validate`` and ``schema`` start fast.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from typing import Callable, Sequence

from .errors import SpecError, UsageError

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2


def _print_problems(error: SpecError) -> None:
    for problem in error.problems:
        print(problem, file=sys.stderr)


# --------------------------------------------------------------------------------------------
# validate / compile / schema


def cmd_validate(args: argparse.Namespace) -> int:
    from .resolve import validate_all_robots
    from .spec.load import load_spec

    status = EXIT_OK
    for path in args.paths:
        try:
            loaded = load_spec(path)
            resolved = validate_all_robots(loaded)
        except SpecError as exc:
            _print_problems(exc)
            status = EXIT_BAD_INPUT
            continue
        robots = ", ".join(r.robot_name for r in resolved)
        print(f"{path}: ok (task '{loaded.spec.name}', robots: {robots})")
    return status


def cmd_compile(args: argparse.Namespace) -> int:
    from .compile.compiler import compile_task

    result = compile_task(args.spec, args.robot, args.out, force=args.force)
    m = result.manifest
    if args.strict:
        from .compile.external_checks import check_with_urdfdom, check_with_yourdfpy, pybullet_load_warnings

        failures = []
        for body in m.bodies:
            path = result.out_dir / body.urdf
            for check in (check_with_urdfdom, check_with_yourdfpy, pybullet_load_warnings):
                failures += [f"{path}: {check.__name__}: {line}" for line in check(path)]
        if failures:
            print("\n".join(failures), file=sys.stderr)
            return EXIT_FAILED
    state = "up to date (cache hit)" if result.cache_hit else "compiled"
    print(
        f"{state}: {m.task} for {m.robot_name} -> {result.out_dir}/ "
        f"({len(m.bodies)} bodies, id {m.gym_id}, content {m.content_hash[:12]}) in {result.seconds:.2f} s"
    )
    return EXIT_OK


def task_schema() -> dict:
    """JSON Schema of a task spec, with the registered term and preference names as enums."""
    from .spec.models import PREFERENCE_NAMES, TaskSpec
    from .terms.registry import terms

    schema = TaskSpec.model_json_schema()
    defs = schema.get("$defs", {})
    if "TermUse" in defs:
        defs["TermUse"]["properties"]["term"]["enum"] = sorted(terms("observation"))
    if "RewardTerm" in defs:
        defs["RewardTerm"]["properties"]["term"]["enum"] = sorted(terms("reward"))
    if "Preferences" in defs:
        defs["Preferences"]["properties"]["active"]["propertyNames"] = {"enum": list(PREFERENCE_NAMES)}
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "assistive-compiler task spec"
    return schema


def cmd_schema(args: argparse.Namespace) -> int:
    if args.training:
        from .training.config import training_schema

        print(json.dumps(training_schema(), indent=2, sort_keys=True))
        return EXIT_OK
    if args.terms:
        from .terms.registry import terms

        for category in ("observation", "reward", "preference"):
            print(f"{category} terms:")
            for name, tdef in sorted(terms(category).items()):
                fields = ", ".join(tdef.params.model_fields) or "-"
                print(f"  {name:20s} ({fields}) {tdef.summary()}")
        return EXIT_OK
    print(json.dumps(task_schema(), indent=2, sort_keys=True))
    return EXIT_OK


def cmd_list(args: argparse.Namespace) -> int:
    from .paths import display
    from .registration import shipped_tasks

    tasks = shipped_tasks()
    if args.json:
        print(json.dumps([{"task": t.name, "title": t.title, "spec": display(t.spec), "robots": t.robots, "ids": t.ids} for t in tasks], indent=2))
        return EXIT_OK
    robots = sorted({r for t in tasks for r in t.robots})
    print(f"{len(tasks)} tasks x {len(robots)} robots ({', '.join(robots)}); Gymnasium ids (gymnasium.make after import assistive_compiler):")
    for t in tasks:
        print(f"  {t.title} ({t.name}, {display(t.spec)})")
        for robot, env_id in zip(t.robots, t.ids):
            print(f"    {robot:8s} {env_id}")
    return EXIT_OK


# --------------------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="assistive-compiler", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("validate", help="check task specs; print PATH:LINE:COL: problem for each mistake")
    p.add_argument("paths", nargs="+", help="task spec files")
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("compile", help="compile a task spec for a robot into URDFs and a manifest")
    p.add_argument("spec", help="task spec file")
    p.add_argument("--robot", help="robot name (default: the spec's default robot)")
    p.add_argument("--out", help="output directory (default: generated/<task>-<robot>)")
    p.add_argument("--force", action="store_true", help="recompile even when the output is up to date")
    p.add_argument("--strict", action="store_true", help="also check every URDF with urdfdom, yourdfpy and pybullet")
    p.set_defaults(func=cmd_compile)

    p = sub.add_parser("list", help="list the shipped tasks, their robots and Gymnasium ids")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_list)

    p = sub.add_parser("schema", help="print the JSON Schema of a task spec (or --terms: the term library)")
    p.add_argument("--terms", action="store_true", help="list registered terms and their parameters instead")
    p.add_argument("--training", action="store_true", help="print the JSON Schema of a training config (specs/training/*.yaml) instead")
    p.set_defaults(func=cmd_schema)

    _add_runtime_commands(sub)
    return parser


def _add_runtime_commands(sub) -> None:
    try:
        from . import cli_run
    except ImportError:  # pragma: no cover - the runtime commands ship with the package
        return
    cli_run.add_commands(sub)
    from . import cli_train

    cli_train.add_commands(sub)


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        return func(args)
    except SpecError as exc:
        _print_problems(exc)
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


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

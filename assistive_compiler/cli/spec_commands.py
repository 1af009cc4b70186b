"""The spec commands: ``validate``, ``compile``, ``schema`` and ``list``.

They read and compile specs and print what they found; none of them runs physics (``compile``
only to precompute). Heavy modules are imported by the command that needs them, so ``validate``
and ``schema`` start fast.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..errors import SpecError
from .common import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, SPEC_HELP, add_library_argument, print_problems


def cmd_validate(args: argparse.Namespace) -> int:
    from ..resolve import validate_all_robots
    from ..spec.load import load_spec

    status = EXIT_OK
    for path in args.paths:
        try:
            loaded = load_spec(path)
            resolved = validate_all_robots(loaded)
        except SpecError as exc:
            print_problems(exc)
            status = EXIT_BAD_INPUT
            continue
        robots = ", ".join(r.robot_name for r in resolved)
        print(f"{path}: ok (task '{loaded.spec.name}', robots: {robots})")
    return status


def cmd_compile(args: argparse.Namespace) -> int:
    from ..compile.compiler import compile_task

    result = compile_task(args.spec, args.robot, args.out, force=args.force)
    m = result.manifest
    if args.strict:
        from ..compile.external_checks import check_with_urdfdom, check_with_yourdfpy, pybullet_load_warnings

        failures = []
        for body in m.bodies:
            path = result.out_dir / body.urdf
            for check in (check_with_urdfdom, check_with_yourdfpy, pybullet_load_warnings):
                failures += [f"{path}: {check.__name__}: {line}" for line in check(path)]
        if failures:
            print("\n".join(failures), file=sys.stderr)
            return EXIT_FAILED
    from ..gym_ids import TASK_ID

    state = "up to date (cache hit)" if result.cache_hit else "compiled"
    print(
        f"{state}: {m.task} for {m.robot_name} -> {result.out_dir}/ "
        f"({len(m.bodies)} bodies, id {m.gym_id}, content {m.content_hash[:12]}) in {result.seconds:.2f} s"
    )
    if m.gym_id == TASK_ID:  # not a shipped task: say how Gymnasium makes it
        print(f'  not a shipped task: gym.make("{TASK_ID}", spec="{args.spec}", robot="{m.robot_name}") makes it')
    return EXIT_OK


def task_schema() -> dict:
    """JSON Schema of a task spec, with the registered term and preference names as enums."""
    from ..spec.models import PREFERENCE_NAMES, TaskSpec
    from ..terms.catalog import terms

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
        from ..training.config import training_schema

        print(json.dumps(training_schema(), indent=2, sort_keys=True))
        return EXIT_OK
    if args.terms:
        from ..terms.catalog import terms
        from .output import print_table

        for category in ("observation", "reward", "preference"):
            rows = [
                [name, ", ".join(tdef.params.model_fields) or "-", tdef.summary()]
                for name, tdef in sorted(terms(category).items())
            ]
            print_table(
                ["term", "parameters", "what it is"],
                rows,
                left=["term", "parameters", "what it is"],
                title=f"{category} terms",
            )
        return EXIT_OK
    print(json.dumps(task_schema(), indent=2, sort_keys=True))
    return EXIT_OK


def cmd_list(args: argparse.Namespace) -> int:
    """The shipped tasks by the names that work from any directory (``run feeding``, the ids);
    the folder holding their files is said once, for copying or ``extends: shipped:tasks/...``."""
    from ..gym_ids import shipped_tasks
    from ..paths import specs_dir

    tasks = shipped_tasks()
    if args.json:
        print(
            json.dumps(
                [
                    {
                        "task": t.name,
                        "title": t.title,
                        "spec": f"shipped:tasks/{t.spec.name}",
                        "file": str(t.spec),
                        "robots": t.robots,
                        "ids": t.ids,
                    }
                    for t in tasks
                ],
                indent=2,
            )
        )
        return EXIT_OK
    from .output import print_table

    robots = sorted({r for t in tasks for r in t.robots})
    print(
        f"{len(tasks)} tasks x {len(robots)} robots ({', '.join(robots)}). Name a task by its name from any directory "
        f"(assistive-compiler run {tasks[0].name} --robot {tasks[0].robots[0]}), in a spec as shipped:tasks/<name>.yaml "
        "(extends:), or by its Gymnasium id (gymnasium.make after import assistive_compiler, or on the command line):"
    )
    rows, ends = [], []
    for t in tasks:
        for k, (robot, env_id) in enumerate(zip(t.robots, t.ids)):
            rows.append([f"{t.title}" if k == 0 else "", t.name if k == 0 else "", robot, env_id])
        ends.append(len(rows) - 1)
    columns = ["task", "name", "robot", "Gymnasium id"]
    print_table(columns, rows, left=columns, section_after=ends[:-1])
    print(f"(the spec files, to read or copy: {specs_dir() / 'tasks'})")
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser("validate", help="check task specs; print PATH:LINE:COL: problem for each mistake")
    add_library_argument(p)
    p.add_argument(
        "paths", nargs="+", help="task spec files, or shipped task names (feeding) or shipped:tasks/<name>.yaml"
    )
    p.set_defaults(func=cmd_validate)

    p = sub.add_parser("compile", help="compile a task spec for a robot into URDFs and a manifest")
    add_library_argument(p)
    p.add_argument("spec", help=SPEC_HELP)
    p.add_argument("--robot", help="robot name (default: the spec's default robot)")
    p.add_argument(
        "--out",
        "--out-dir",
        dest="out",
        help="output directory (default: generated/<task>-<robot>); --out-dir is the same",
    )
    p.add_argument("--force", action="store_true", help="recompile even when the output is up to date")
    p.add_argument("--strict", action="store_true", help="also check every URDF with urdfdom, yourdfpy and pybullet")
    p.set_defaults(func=cmd_compile)

    p = sub.add_parser("list", help="list the shipped tasks, their robots and Gymnasium ids")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_list)

    p = sub.add_parser("schema", help="print the JSON Schema of a task spec (or --terms: the term library)")
    p.add_argument("--terms", action="store_true", help="list registered terms and their parameters instead")
    p.add_argument(
        "--training",
        action="store_true",
        help="print the JSON Schema of a training config (specs/training/*.yaml) instead",
    )
    p.set_defaults(func=cmd_schema)

    p = sub.add_parser(
        "person-reference", help="write the person model's reference page (links, frames, joints and limits)"
    )
    p.add_argument(
        "--out", default="docs/person.md", help="output Markdown file (default docs/person.md); '-' prints it"
    )
    p.set_defaults(func=cmd_person_reference)


def cmd_person_reference(args: argparse.Namespace) -> int:
    from ..person.reference_page import person_reference_markdown

    text = person_reference_markdown()
    if args.out == "-":
        print(text, end="")
        return EXIT_OK
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    print(f"wrote {args.out}")
    return EXIT_OK

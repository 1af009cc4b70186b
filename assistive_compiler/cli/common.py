"""What every command shares: exit statuses, printing located problems, common arguments.

Exit status: 0 success, 2 bad input (problems printed one per line as ``PATH:LINE:COL: message``),
1 a run that failed for another stated reason.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from ..errors import SpecError

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
EXIT_INTERRUPTED = 130

TRAIN_EXTRA_HINT = (
    "the learning commands need the 'train' extra: install torch's CPU build first "
    "(pip install torch --index-url https://download.pytorch.org/whl/cpu), then pip install -e '.[train]'"
)


def print_problems(error: SpecError) -> None:
    for problem in error.problems:
        print(problem, file=sys.stderr)


def add_library_argument(p: argparse.ArgumentParser) -> None:
    """``--library DIR`` (repeatable): a folder of the user's own parts, laid out like ``specs/``."""
    p.add_argument(
        "--library",
        action="append",
        default=[],
        metavar="DIR",
        help="a folder of your own parts (robots/ tools/ furniture/ people/, templates in ../templates); "
        "repeatable; searched before $ASSISTIVE_COMPILER_LIBRARY, the spec's own library and the shipped parts",
    )


def use_library_dirs(dirs: list[str]) -> None:
    """Put ``--library`` folders in front of ``$ASSISTIVE_COMPILER_LIBRARY`` for this process, so
    every compile the command makes (and any worker it starts) finds them."""
    from ..library import LIBRARY_ENV

    for d in dirs:
        if not Path(d).is_dir():
            raise SpecError.at(
                d, "--library: folder not found (expected a folder holding robots/, tools/, furniture/ or people/)"
            )
    if dirs:
        current = [p for p in os.environ.get(LIBRARY_ENV, "").split(os.pathsep) if p]
        os.environ[LIBRARY_ENV] = os.pathsep.join([str(Path(d).resolve()) for d in dirs] + current)


SPEC_HELP = (
    "task spec: a file, a shipped task's name (feeding; `list` shows them), shipped:tasks/<name>.yaml, "
    "or a Gymnasium id (FeedingJaco-v1: the task and its robot)"
)


def spec_from_gym_id(args: argparse.Namespace) -> None:
    """A Gymnasium id given as the spec (``assistive_compiler/FeedingJaco-v1`` or ``FeedingJaco-v1``)
    names the shipped task's file and its robot: ``args.spec`` becomes ``shipped:tasks/<file>``
    and ``args.robot`` its robot (a different ``--robot`` is a usage error)."""
    from ..errors import UsageError
    from ..gym_ids import NAMESPACE, shipped_ids

    spec = getattr(args, "spec", None)
    if not isinstance(spec, str) or not spec.endswith("-v1") or Path(spec).exists():
        return
    found = shipped_ids().get(spec if spec.startswith(f"{NAMESPACE}/") else f"{NAMESPACE}/{spec}")
    if found is None:
        return
    path, robot = found
    if getattr(args, "robot", None) not in (None, robot):
        raise UsageError(f"{spec} is the task for robot '{robot}', but --robot is '{args.robot}'; give one of them")
    args.spec, args.robot = f"shipped:tasks/{path.name}", robot


def add_spec_arguments(p: argparse.ArgumentParser, policy: bool = True) -> None:
    """``spec``, ``--robot``, ``--policy`` (optional), ``--seed`` and ``--library``: what a rollout command needs."""
    from ..policies import POLICY_HELP

    add_library_argument(p)
    p.add_argument("spec", help=SPEC_HELP)
    p.add_argument("--robot", help="robot (default: the spec's default)")
    if policy:
        p.add_argument("--policy", default="scripted", help=f"policy to roll out: {POLICY_HELP} (default scripted)")
    p.add_argument("--seed", type=int, default=0, help="first episode seed")


class _ArtifactOut(argparse.Action):
    """``--out`` where it names the artifact directory (``run``, ``view``, ``compare``): the older
    spelling of ``--out-dir``, still read, with a note on stderr (``--out`` is what a command
    writes: ``render``'s picture, ``compile``'s artifact)."""

    def __call__(self, parser, namespace, values, option_string=None):
        print(
            f"{parser.prog}: --out here is the older spelling of --out-dir (the artifact directory, as in render, "
            "where --out is the picture); it still works",
            file=sys.stderr,
        )
        setattr(namespace, self.dest, values)


def add_artifact_argument(p: argparse.ArgumentParser, what: str = "artifact directory") -> None:
    """``--out-dir DIR``: where the task is compiled to (every command that compiles as a means, not
    as its product, spells it so); ``--out`` is accepted as its older spelling, with a note."""
    p.add_argument("--out-dir", dest="out", metavar="DIR", help=f"{what} (default generated/<task>-<robot>)")
    p.add_argument("--out", dest="out", action=_ArtifactOut, help=argparse.SUPPRESS)


def make_env(spec: str, robot: str | None, out: str | None = None, **kwargs):
    """The env of ``spec`` for ``robot``, compiled into ``out`` first (a cache hit when unchanged)."""
    from ..runtime.env import AssistiveEnv

    return AssistiveEnv.from_spec(spec, robot=robot, out_dir=out, **kwargs)


def require_extra(*modules: str) -> bool:
    """Whether the optional ``modules`` (of the ``train`` extra) are installed; says how to install them if not."""
    import importlib.util

    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        print(f"error: {', '.join(missing)} not installed; {TRAIN_EXTRA_HINT}", file=sys.stderr)
    return not missing

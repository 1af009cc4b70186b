"""``train``: learn a policy with PPO — Stable-Baselines3 on one machine, Ray RLlib for
co-optimisation (``--coop``) and Ray clusters (``--address``). The work is in
:mod:`assistive_compiler.training`; it needs the optional ``train`` extra, which the package
itself never imports."""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from ..run_dir import engine_modules
from .common import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, SPEC_HELP, add_library_argument, require_extra


def shipped_configs() -> str:
    """The shipped training configs by name (specs/training/*.yaml), for the help text."""
    from ..paths import specs_dir

    return ", ".join(sorted(p.stem for p in (specs_dir() / "training").glob("*.yaml")))


def training_config_path(name: str) -> str:
    """A config path as given, or a shipped config by name (``ppo_quick`` -> specs/training/ppo_quick.yaml)."""
    from ..paths import specs_dir

    if Path(name).exists() or "/" in name or name.endswith((".yaml", ".yml")):
        return name
    return str(specs_dir() / "training" / f"{name}.yaml")


def _summary_line(summary: dict) -> str:
    ret, rate = summary["final_mean_return"], summary["final_success_rate"]
    return (
        f"{summary['gym_id']}: {summary['steps']:,} steps in {summary['wall_s']:.0f} s "
        f"({summary['steps_per_s_including_learning']:.0f} steps/s including learning); "
        f"last mean return {'-' if ret is None else f'{ret:.1f}'}, success {'-' if rate is None else f'{rate:.2f}'}; "
        f"checkpoint {summary['checkpoint']}"
    )


def _stdout_for_the_summary_alone():
    """For ``--json``: a stream on the process's stdout for the summary, with file descriptor 1
    pointed at stderr for the rest of the process, so that whatever else is written to stdout —
    training's prints, and Ray's forwarded cluster messages (e.g. "raylet ... died"), which can
    arrive from its threads or at interpreter exit, after the summary — goes to stderr."""
    sys.stdout.flush()
    summary_out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    return summary_out


def cmd_train(args: argparse.Namespace) -> int:
    from ..training.train import choose_engine

    engine = choose_engine(args.engine, args.coop, args.address)  # a bad --engine is reported before heavy imports
    if args.coop:  # a person with nothing to control is the spec's mistake: say so before asking for installs
        from ..coop.parallel import check_coop_spec
        from ..spec.load import load_spec

        check_coop_spec(load_spec(args.spec))
    from ..training.config import load_training_config

    library = load_training_config(training_config_path(args.config)).library
    if not require_extra(*engine_modules(engine, library)):
        return EXIT_FAILED
    from ..training.train import train

    summary_out = _stdout_for_the_summary_alone() if args.json else sys.stdout
    summary = train(
        args.spec,
        robot=args.robot,
        config_path=training_config_path(args.config),
        coop=args.coop,
        engine=engine,
        steps=args.steps,
        seed=args.seed,
        envs=args.envs,
        out=args.out,
        resume=args.resume,
        address=args.address,
        quiet=args.quiet,
        demonstrations=args.demonstrations,
        demonstrations_root=args.demonstrations_root,
    )
    print(json.dumps(summary, indent=1) if args.json else _summary_line(summary), file=summary_out, flush=True)
    if summary["interrupted"]:
        print(
            f"stopped: {summary['stopped_because']}"
            if summary.get("stopped_because")
            else "interrupted: checkpoint written; continue with the same command and --resume",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser(
        "train",
        help="learn a policy with PPO or SAC (SB3 on one machine; RLlib for --coop and Ray clusters)",
        description="Learn a policy for a task. Which config, by the clock (docs/results.md, 'The recipe by the "
        "clock'), one run per core (taskset -c N): sac_one_core (SAC, 2x64, learned by SBX/JAX: 2-3.5 times "
        "sac_laptop's env steps per core-hour) for Feeding and the slow envs (Drinking, Dressing); "
        "ppo_paper_in_process (the paper's PPO, its 36 envs in one process) for "
        "Itch Scratching, whose success is a motion; ppo_one_core for the most env steps per hour and a working "
        "policy soonest (Arm Manipulation); sac_laptop (SB3, PyTorch) for the higher final figures and what SBX does not do: "
        "--demonstrations, the averaged actor, layer-normalised or conservative critics. Co-optimisation on one core: "
        "--coop --engine sb3 with ppo_paper_in_process or sac_laptop (one actor per agent, one shared critic).",
    )
    add_library_argument(p)
    p.add_argument("spec", help=SPEC_HELP)
    p.add_argument("--robot", help="robot name (default: the spec's default robot)")
    p.add_argument(
        "--config", required=True, help=f"training config: a file, or a shipped one by name ({shipped_configs()})"
    )
    p.add_argument(
        "--coop", action="store_true", help="co-optimisation: train the robot and the person (policies robot and human)"
    )
    p.add_argument(
        "--engine", default="auto", help="sb3 | rllib | auto (default: rllib for --coop or --address, else sb3)"
    )
    p.add_argument("--address", help="attach to a running Ray cluster at HOST:PORT (or ray://HOST:PORT, or auto)")
    p.add_argument("--steps", type=int, help="total env steps (overrides the config's total_steps)")
    p.add_argument("--seed", type=int, help="seed (overrides the config's)")
    p.add_argument(
        "--envs",
        type=int,
        help="envs collecting experience (overrides the config's; each a process, or all in the trainer's process under vec_env: in_process)",
    )
    p.add_argument("--out", help="run directory (default: runs/<task>-<robot>[-coop]-s<seed>)")
    p.add_argument("--resume", action="store_true", help="continue the run in --out from its newest checkpoint")
    p.add_argument(
        "--demonstrations",
        metavar="DATASET",
        help="start a new SAC run from a Minari dataset of this task (collect): clone its successful episodes' "
        "actions, then put all its transitions in the replay buffer (needs the datasets extra)",
    )
    p.add_argument(
        "--demonstrations-root", metavar="DIR", help="datasets directory of --demonstrations (as collect --root)"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar or reward table")
    p.add_argument("--json", action="store_true", help="print the run's summary as JSON")
    p.set_defaults(func=cmd_train)

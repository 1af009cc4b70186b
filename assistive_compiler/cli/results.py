"""``export`` (a run's newest checkpoint as a shipped-policy folder, evaluated) and ``results``
(``docs/results.md``'s tables, curves and pictures from the shipped policies). The work is in
:mod:`assistive_compiler.training.trained.export` and :mod:`assistive_compiler.training.results.results_page`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..run_dir import engine_modules
from .common import EXIT_FAILED, EXIT_OK, require_extra


def cmd_export(args: argparse.Namespace) -> int:
    from ..run_dir import RunDir

    info = RunDir(args.run_dir).info()
    if not require_extra(*engine_modules(info.engine, info.library)):
        return EXIT_FAILED
    from ..paths import display
    from ..training.trained.export import export_run

    record = export_run(
        args.run_dir,
        args.out,
        episodes=args.episodes,
        seed=args.seed,
        label=args.label or "",
        progress=lambda line: print(line, file=sys.stderr),
        checkpoint_steps=args.checkpoint,
    )
    e = record["evaluation"]
    where = display(Path(args.out)) if args.out else f"pretrained/{record['name']}"
    play = where if args.out else f"pretrained:{record['name']}"
    print(
        f"exported {record['gym_id']} ({record['trained_steps']:,} steps) -> {where}: success {e['success_rate']:.2f}, "
        f"return {e['mean_return']:.1f} ± {e['std_return']:.1f} over {e['episodes']} episodes from seed {e['seed']:,}; "
        f"play it with --policy {play}"
    )
    return EXIT_OK


def _reevaluate(names: list[str]) -> list[str]:
    """``results --reevaluate``: measure the named shipped policies (none named: those whose figures
    were measured on another compile of their task) again on the current code; their names."""
    from ..errors import UsageError, did_you_mean, one_of
    from ..policies.pretrained import shipped_names
    from ..training.trained.reevaluate import reevaluate_shipped, stale_figures

    shipped = shipped_names()
    for name in names:  # an unknown name is a clear error before any work
        if name not in shipped:
            raise UsageError(
                f"results --reevaluate: no shipped policy {name}; shipped: {one_of(shipped)}{did_you_mean(name, shipped)}"
            )
    chosen = names or [s.name for s in stale_figures(shipped)]
    for name in chosen:
        record = reevaluate_shipped(name, progress=lambda line, name=name: print(f"{name}: {line}", file=sys.stderr))
        print(f"re-evaluated {name} on the task compiled now ({record['evaluated_on_content_hash'][:12]})")
    if chosen:
        print(
            "now record their regression episodes from these evaluations: "
            "python -m tests.pretrained_regression --write --from-evaluation " + " ".join(chosen)
        )
    return chosen


def _say_which_figures_are_stale(names: list[str]) -> None:
    from ..training.trained.reevaluate import stale_figures

    stale = stale_figures(names)
    if stale:
        print(
            f"{len(stale)} shipped polic{'y was' if len(stale) == 1 else 'ies were'} evaluated on another compile of "
            f"the task than the current code's, so {'its' if len(stale) == 1 else 'their'} figures are not today's: "
            + "; ".join(str(s) for s in stale)
            + ". `assistive-compiler results --reevaluate` measures them again.",
            file=sys.stderr,
        )


def cmd_results(args: argparse.Namespace) -> int:
    if args.reevaluate is not None:
        _reevaluate(args.reevaluate)
    if not args.no_pictures and not require_extra("matplotlib"):
        return EXIT_FAILED
    from ..paths import display
    from ..training.results.results_page import shipped_records, update_doc, write_pictures

    doc = Path(args.out)
    records = shipped_records()
    _say_which_figures_are_stale([r["name"] for r in records])
    if args.pictures_of:
        unknown = sorted(set(args.pictures_of) - {r["name"] for r in records})
        if unknown:
            from ..errors import UsageError

            raise UsageError(f"results --pictures-of: no shipped policy {', '.join(unknown)} (see pretrained/)")
    drawn = [r for r in records if not args.pictures_of or r["name"] in args.pictures_of]
    if not args.no_pictures:
        write_pictures(drawn, doc.parent, progress=lambda name: print(f"pictures of {name}", file=sys.stderr))
    doc.parent.mkdir(parents=True, exist_ok=True)
    doc.write_text(update_doc(doc, records))
    print(f"wrote {display(doc)} from {len(records)} shipped polic{'y' if len(records) == 1 else 'ies'}")
    return EXIT_OK


def add_commands(sub) -> None:
    from ..training.trained.export import EVAL_SEED

    p = sub.add_parser(
        "export", help="a run's newest checkpoint as a shipped policy (NumPy only), evaluated on unseen seeds"
    )
    p.add_argument("run_dir", help="a run directory written by train (SB3 or RLlib; static or co-optimised)")
    p.add_argument(
        "--out",
        help="policy folder (default pretrained/<task>-<robot>, co-optimised pretrained/<task>-<robot>-coop: "
        "shipped as pretrained:<that name>)",
    )
    p.add_argument("--episodes", type=int, default=100, help="evaluation episodes (default 100, as the paper)")
    p.add_argument(
        "--seed",
        type=int,
        default=EVAL_SEED,
        help=f"first evaluation seed (default {EVAL_SEED:,}: never used in training)",
    )
    p.add_argument("--label", help="the table row's name (default: the algorithm and its config's description)")
    p.add_argument(
        "--checkpoint",
        type=int,
        metavar="STEPS",
        help="the run's checkpoint at this many env steps (default: the newest), e.g. to ship a cell at "
        "the budget of the cell it is compared with",
    )
    p.set_defaults(func=cmd_export)

    p = sub.add_parser(
        "results", help="regenerate docs/results.md's tables, curves and pictures from the shipped policies"
    )
    p.add_argument("--out", default="docs/results.md", help="the results document (its generated block is replaced)")
    p.add_argument(
        "--no-pictures", action="store_true", help="tables only; keep the curve and rollout pictures as they are"
    )
    p.add_argument(
        "--pictures-of",
        nargs="+",
        metavar="NAME",
        help="draw only these cells' pictures (e.g. newly shipped ones); the tables still cover every cell",
    )
    p.add_argument(
        "--reevaluate",
        nargs="*",
        metavar="NAME",
        help="first evaluate these shipped policies again on the task the current code compiles (none named: "
        "every one whose figures were measured on another compile), then write the page",
    )
    p.set_defaults(func=cmd_results)

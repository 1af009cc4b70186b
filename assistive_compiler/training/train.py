"""``train``: compile the task, open (or resume) a run directory, and hand it to an engine.

Engines: ``sb3`` (Stable-Baselines3 PPO or SAC on one machine; with ``--coop``, one actor per
agent and one shared critic) and ``rllib`` (Ray RLlib PPO or SAC: co-optimisation with policies
``robot`` and ``human``, or any run on a Ray cluster via ``--address``). ``auto`` picks RLlib for
``--coop`` or an ``--address``, SB3 otherwise.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from pathlib import Path

from ..errors import UsageError
from ..paths import display
from ..run_dir import RunDir
from .bookkeeping.resume import check_resumable, new_run_info
from .config import TrainingConfig, load_training_config, run_config

ENGINES = ("auto", "sb3", "rllib")


def choose_engine(engine: str, coop: bool, address: str | None) -> str:
    from ..errors import did_you_mean, one_of

    if engine not in ENGINES:
        raise UsageError(
            f"--engine: unknown engine '{engine}'; expected one of {one_of(ENGINES)}{did_you_mean(engine, ENGINES)}"
        )
    if engine == "auto":
        return "rllib" if coop or address else "sb3"
    if engine == "sb3" and address:
        raise UsageError("--address attaches to a Ray cluster: use --engine rllib (or auto)")
    return engine


def compile_for_run(spec: str, robot: str | None, coop: bool):
    """Compile the task (cached in the artifact cache) and check it can be trained as asked."""
    from ..compile.compiler import compile_task
    from ..registration import cache_dir
    from ..spec.load import load_spec

    loaded = load_spec(spec)
    if coop:
        from ..coop.parallel import check_coop_spec

        check_coop_spec(loaded)  # located: the person must control joints and observe something
    robot = robot or loaded.spec.robot.default
    result = compile_task(spec, robot, cache_dir() / f"{loaded.spec.name}-{robot}")
    return result, robot


def reward_weights(manifest) -> dict[str, float]:
    """Each reward term's weight, by name (preference costs included)."""
    return {t.name: t.weight for t in manifest.reward}


def default_run_dir(task: str, robot: str, coop: bool, seed: int) -> Path:
    return Path("runs") / f"{task}-{robot}{'-coop' if coop else ''}-s{seed}"


def train(
    spec: str,
    *,
    robot: str | None,
    config_path: str,
    coop: bool = False,
    engine: str = "auto",
    steps: int | None = None,
    seed: int | None = None,
    envs: int | None = None,
    out: str | None = None,
    resume: bool = False,
    address: str | None = None,
    quiet: bool = False,
    demonstrations: str | None = None,
    demonstrations_root: str | None = None,
) -> dict:
    """Train a policy for ``spec`` and ``robot`` as ``config_path`` says; returns the run's summary.
    ``demonstrations``: a Minari dataset id of the same task to start a new SAC run from
    (:mod:`.learners.demonstrations`)."""
    engine = choose_engine(engine, coop, address)
    if demonstrations is not None and resume:
        raise UsageError(
            "--demonstrations starts a new run; --resume continues one with the demonstrations it started from"
        )
    if demonstrations is not None and (engine != "sb3" or coop):
        raise UsageError("--demonstrations: starting from demonstrations is for single-agent SB3 SAC (--engine sb3)")
    config: TrainingConfig = load_training_config(config_path).with_overrides(
        steps=steps, seed=seed, envs=envs, demonstrations=demonstrations, demonstrations_root=demonstrations_root
    )
    if engine == "sb3" and coop and config.library == "sbx":
        raise UsageError(
            f"--coop --engine sb3 trains one actor per agent, built on SB3's PyTorch PPO and SAC; "
            f"{display(Path(config_path))} learns with sbx (sac.library): use a config with library: sb3 "
            "(e.g. sac_laptop, or ppo_paper_in_process)"
        )
    if engine == "rllib":
        from .engines.rllib import check_supported

        check_supported(config)  # settings only SB3 builds are refused before anything is compiled or written
    result, robot = compile_for_run(spec, robot, coop)
    if engine == "rllib":
        from .engines.rllib import init_ray

        init_ray(address, config.envs)  # an unreachable cluster fails here, before the run directory is written
    manifest = result.manifest
    run = RunDir(out or default_run_dir(manifest.task, robot, coop, config.seed))
    if resume:
        info = check_resumable(run, manifest.content_hash, robot, coop, engine)
        resumed = run_config(info)
        for flag, given, kept in (("--seed", seed, resumed.seed), ("--envs", envs, resumed.envs)):
            if given is not None and given != kept:
                raise UsageError(
                    f"{flag} {given}: --resume continues the run with its own config ({flag} {kept}); only --steps may change"
                )
        config = resumed.with_overrides(steps=steps)
    elif run.exists():
        raise UsageError(
            f"{display(run.path)}: the run directory already holds a run; pass --resume to continue it, or choose another --out"
        )
    # read and checked before the run directory is written; a resumed run reads them again for its actor's updates
    demo_data = read_demonstrations(config, config_path, manifest.content_hash, resume)
    if not resume:
        run.create(new_run_info(spec, manifest, robot, coop, engine, config), result.out_dir)
    weights = reward_weights(manifest)
    if not quiet:
        from .bookkeeping.progress import print_reward_table

        print(
            f"{manifest.label}{' + human (co-optimisation)' if coop else ''}: {engine} {config.algorithm.upper()}, {config.envs} envs, "
            f"{config.total_steps:,} steps -> {display(run.path)}",
            file=sys.stderr,
        )
        print_reward_table(weights, manifest.task)
    with stop_on_signals() as stop:
        if engine == "sb3":
            from .engines import sb3

            figures = sb3.train(
                run, config, weights, resume=resume, quiet=quiet, stop=stop, demonstrations=demo_data, coop=coop
            )
        else:
            from .engines import rllib

            figures = rllib.train(
                run, config, weights, coop=coop, resume=resume, address=address, quiet=quiet, stop=stop
            )
    return finish(run, manifest, engine, config, figures)


def read_demonstrations(config: TrainingConfig, config_path: str, content_hash: str, resume: bool):
    """The demonstrations a config with a ``demonstrations`` block starts from (a new run) or keeps
    cloning in its actor's updates (a resumed one), read and checked against the run's compiled
    task (``content_hash``); None where the run does not read them."""
    demo_data = None
    d = config.demonstrations
    if d is not None and (not resume or d.steers_actor_updates):
        from .learners.demonstrations import load_demonstrations

        if d.dataset is None:
            raise UsageError(
                f"{display(Path(config_path))}: this config starts from demonstrations; "
                "name the dataset with --demonstrations DATASET (a `collect` dataset of this task)"
            )
        demo_data = load_demonstrations(d, content_hash)
    return demo_data


class StopRequest:
    """Set when the user asks training to stop (Ctrl-C, or SIGTERM from a scheduler or ``kill``).
    The engines look at it at safe points — SB3 after each env step, RLlib after each iteration —
    then write a checkpoint and return, so a stop never lands inside torch, TensorBoard's writer
    or a checkpoint being written."""

    def __init__(self) -> None:
        self.requested = False

    def __bool__(self) -> bool:
        return self.requested


@contextlib.contextmanager
def stop_on_signals():
    """While training, SIGINT and SIGTERM set a :class:`StopRequest` instead of raising; a second
    signal interrupts at once (KeyboardInterrupt; the engine still checkpoints on its way out).
    Only the main thread can install signal handlers: elsewhere the request is never set."""
    stop = StopRequest()
    if threading.current_thread() is not threading.main_thread():
        yield stop
        return

    def request(signum, frame):
        if stop.requested:
            raise KeyboardInterrupt
        stop.requested = True

    previous = {sig: signal.signal(sig, request) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield stop
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def finish(run: RunDir, manifest, engine: str, config: TrainingConfig, figures: dict) -> dict:
    """Write the learning-curve figure and ``summary.json``; returns the summary."""
    from .bookkeeping.curves import plot_curves, read_curve

    curve = read_curve(run.curve_csv)
    tail = curve[-5:]
    summary = {
        "gym_id": manifest.gym_id,
        "engine": engine,
        **figures,
        "total_steps_configured": config.total_steps,
        "envs": config.envs,
        "episodes": curve[-1]["episodes"] if curve else 0,
        "final_mean_return": sum(r["mean_return"] for r in tail) / len(tail) if tail else None,
        "final_success_rate": sum(r["success_rate"] for r in tail) / len(tail) if tail else None,
        "checkpoint": display(run.latest_checkpoint()[1]) if run.latest_checkpoint() else None,
    }
    started_from = run.demonstrations()
    if started_from is not None:
        summary["demonstrations"] = started_from
    if curve:
        plot_curves({run.path.name: curve}, run.curve_png, title=manifest.label)
        summary["learning_curve"] = display(run.curve_png)
    run.write_summary(summary)
    return summary

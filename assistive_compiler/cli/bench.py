"""``bench``: speed figures of (task, robot) pairs, all taken in one run.

Env steps/s against raw physics (the same episodes, physics timed inside ``env.step``) and
against the reference implementation's measured rate — at the spec's solver settings and at the
reference's (an artifact compiled with them), so that no speed claim rests on simulating less —
both agents acting (co-optimisation),
resets, compile times, import time and memory. Each figure comes from a plain ``measure_*``
function (medians over repeats) that other commands may reuse; :func:`bench` takes them all.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from ..errors import SpecError
from .bench_training import add_arguments as add_training_arguments
from .common import EXIT_OK, add_library_argument

_CHILD = r"""
import json, sys, time, numpy as np
t = time.perf_counter()
import assistive_compiler
import_s = time.perf_counter() - t
heavy = sorted(m for m in ("torch", "tensorflow", "jax", "ray", "stable_baselines3", "pybullet") if m in sys.modules)
from assistive_compiler.runtime.env import AssistiveEnv
env = AssistiveEnv(sys.argv[1])
env.reset(seed=0)
for _ in range(200):
    env.step(env.action_space.sample())

def peak_rss_mb():
    # VmHWM: this process's own high-water mark, which starts afresh at exec. Not getrusage's
    # ru_maxrss: Linux carries the parent's high-water mark over fork and exec into it (bench's
    # own ~1 GB was reported as the env's). None where there is no /proc to read it from.
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return None

print(json.dumps({"import_s": import_s, "heavy_modules_on_import": heavy, "peak_rss_mb": peak_rss_mb()}))
"""


REFERENCE_SESSION = (
    "measured side by side on 2026-11-29 with the reference harness (quiet 2-core machine, each side in a fresh "
    "process pinned to one core, interleaved; the reference at its own solver settings on stock pybullet, its "
    "fork-only gravity emulation's time removed; the harness's episodes of random actions)"
)
REFERENCE_PROBE_STEPS_PER_S = (1778.1, 1)
"""The machine probe (:mod:`assistive_compiler.machine_probe`: its steps/s, its version) in
:data:`REFERENCE_SESSION`: the median of 60 probe runs pinned to the harness's core, one after each
pair of harness runs."""

#: Env steps/s of the reference implementation (Assistive Gym v1.0) per (task, robot) on its own
#: pybullet fork, taken in :data:`REFERENCE_SESSION` (medians of 3–4 interleaved rounds;
#: ``benchmarks/reference_side_by_side.py`` takes them again) and carried over to the machine as it
#: runs now by the machine probe. The reference has no Panda or Stretch, and its Dressing needs its
#: fork. ``--reference-json`` replaces them with figures measured beside ours.
REFERENCE_STEPS_PER_S: dict[tuple[str, str], float] = {
    ("feeding", "jaco"): 182.6,
    ("scratch_itch", "jaco"): 328.0,
    ("drinking", "jaco"): 25.5,
    ("bed_bathing", "jaco"): 86.4,
    ("arm_manipulation", "jaco"): 199.8,
    ("feeding", "pr2"): 97.7,
    ("scratch_itch", "pr2"): 159.5,
    ("drinking", "pr2"): 20.3,
    ("bed_bathing", "pr2"): 69.4,
    ("arm_manipulation", "pr2"): 118.9,
    ("feeding", "baxter"): 174.0,
    ("scratch_itch", "baxter"): 234.1,
    ("drinking", "baxter"): 23.9,
    ("bed_bathing", "baxter"): 94.7,
    ("arm_manipulation", "baxter"): 145.4,
    ("feeding", "sawyer"): 195.7,
    ("scratch_itch", "sawyer"): 278.8,
    ("drinking", "sawyer"): 25.0,
    ("bed_bathing", "sawyer"): 85.7,
    ("arm_manipulation", "sawyer"): 158.9,
}


def reference_now(task: str, robot: str, probe_now: float) -> tuple[float, float | None, float, str] | None:
    """The stored reference figure of (task, robot) for this machine now: (the figure as stored,
    this machine's speed now over the stored session's by the probe, the figure carried over by it,
    how it was taken). With a probe of another version than the stored figures were taken beside,
    it is not carried over (speed None, the figure as stored, and the text says so); None where
    the reference was not measured."""
    from ..machine_probe import PROBE_VERSION

    if (task, robot) not in REFERENCE_STEPS_PER_S:
        return None
    stored = REFERENCE_STEPS_PER_S[(task, robot)]
    probe_then, version = REFERENCE_PROBE_STEPS_PER_S
    if version != PROBE_VERSION:
        return (
            stored,
            None,
            stored,
            f"{REFERENCE_SESSION}; not carried over: taken beside machine probe version {version}, "
            f"this is version {PROBE_VERSION} (measure them again: benchmarks/reference_side_by_side.py)",
        )
    speed = probe_now / probe_then
    return (
        stored,
        speed,
        stored * speed,
        f"{REFERENCE_SESSION}; carried over to this machine's speed now by the machine probe "
        "(machine_speed_vs_reference_session)",
    )


def reference_on_fork(row: dict) -> float:
    """Env steps/s of the reference on its own pybullet fork from one harness line (``measure.py ag
    ENV``): its figure on stock pybullet without the time of the harness's gravity emulation, which
    the fork does natively."""
    return float(row["steps_per_s"]) / (1.0 - float(row.get("gravity_shim_share", 0.0)))


def load_reference_json(path: str) -> dict[str, float]:
    """Reference figures measured beside ours: the reference harness's ``measure.py ag ENV`` lines
    (a JSON list or one JSON object per line). Env name (``FeedingJaco``) -> env steps/s of the
    reference on its own pybullet fork (``steps_per_s / (1 - gravity_shim_share)``), median over
    the lines of that env. Located errors for a file that is not such lines."""
    text = Path(path).read_text() if Path(path).is_file() else None
    if text is None:
        raise SpecError.at(
            path, "--reference-json: file not found (lines printed by the reference harness's measure.py ag ENV)"
        )
    try:
        rows = (
            json.loads(text)
            if text.lstrip().startswith("[")
            else [json.loads(line) for line in text.splitlines() if line.strip()]
        )
    except json.JSONDecodeError as exc:
        raise SpecError.at(path, f"--reference-json: not JSON ({exc.msg})", exc.lineno, exc.colno) from None
    figures: dict[str, list[float]] = {}
    for k, row in enumerate(rows):
        if not isinstance(row, dict) or not {"env", "steps_per_s"} <= set(row):
            raise SpecError.at(
                path, "--reference-json: each entry needs 'env' and 'steps_per_s' (measure.py's output)", k + 1
            )
        if row.get("side", "ag") != "ag":
            continue  # our own side's lines, if the file holds both
        figures.setdefault(str(row["env"]), []).append(reference_on_fork(row))
    return {env: statistics.median(v) for env, v in figures.items()}


def _median_p95(values: list[float]) -> tuple[float, float]:
    s = sorted(values)
    return statistics.median(s), s[min(len(s) - 1, int(round(0.95 * (len(s) - 1))))]


def measure_steps(env, steps: int, repeats: int, seed: int) -> tuple[list[float], list[float], list[float]]:
    """Per repeat (one seeded episode of ``steps`` random actions): env steps/s, the same steps' physics
    alone in steps/s (stepSimulation + gravity compensation, timed inside ``env.step``), and the env's
    overhead per step (µs)."""
    env.action_space.seed(seed)
    env_rates, raw_rates, overhead = [], [], []
    for r in range(repeats):
        env.reset(seed=seed + r)
        physics0 = env.physics_s
        t0 = time.perf_counter()
        for _ in range(steps):
            env.step(env.action_space.sample())
        total = time.perf_counter() - t0
        physics = env.physics_s - physics0
        env_rates.append(steps / total)
        raw_rates.append(steps / physics)
        overhead.append((total - physics) / steps * 1e6)
    return env_rates, raw_rates, overhead


def measure_raw_loop(env, steps: int) -> float:
    """Env steps/s of a bare ``stepSimulation`` loop (frame_skip physics steps each) with the scene at rest."""
    import pybullet as pb

    env.reset(seed=0)
    t0 = time.perf_counter()
    for _ in range(steps * env.manifest.sim.frame_skip):
        pb.stepSimulation(physicsClientId=env.client)
    return steps / (time.perf_counter() - t0)


def measure_resets(env, resets: int) -> tuple[list[float], list[float]]:
    """Reset times (ms) after a step: unseeded (restore the saved state: the training path) and
    seeded (rebuild for a bit-exact replay; at most 20)."""
    reset_ms, seeded_ms = [], []
    for _ in range(resets):
        env.step(env.action_space.sample())
        t0 = time.perf_counter()
        env.reset()
        reset_ms.append((time.perf_counter() - t0) * 1e3)
    for k in range(min(resets, 20)):
        env.step(env.action_space.sample())
        t0 = time.perf_counter()
        env.reset(seed=1000 + k)
        seeded_ms.append((time.perf_counter() - t0) * 1e3)
    return reset_ms, seeded_ms


def measure_stages(env, steps: int, seed: int) -> dict[str, float]:
    """Each stage's share of the physics (:mod:`assistive_compiler.profiling`) over one episode of
    ``steps`` seeded random actions, rounded to 0.1%."""
    from ..profiling import profile_episode

    env.action_space.seed(seed)
    shares, _ = profile_episode(env, [env.action_space.sample() for _ in range(steps)], seed)
    return {stage: round(share, 3) for stage, share in shares.items()}


def _percent(shares: dict[str, float]) -> str:
    from .output import MISSING

    return ", ".join(f"{stage} {100 * share:.0f}%" for stage, share in shares.items()) or MISSING


def measure_harness_protocol(env) -> float:
    """Env steps/s the way the reference harness measures both implementations, so that the ratio
    to its figures compares like with like: ``reset(seed=1001)``, ten resets, then two episodes
    (each after an unseeded reset) of 200 steps of uniform random actions in [-1, 1] from numpy's
    ``default_rng(0)``, only ``step`` timed. Episodes differ in cost (in Arm Manipulation the
    male person's costs a quarter more than the female's), so a figure from other episodes is not
    comparable to the reference's."""
    import numpy as np

    env.reset(seed=1001)
    for _ in range(10):
        env.reset()
    rng = np.random.default_rng(0)
    n = env.action_space.shape[0]
    spent, steps = 0.0, 0
    for _ in range(2):
        env.reset()
        for _ in range(200):
            action = rng.uniform(-1, 1, n).astype(np.float32)
            t0 = time.perf_counter()
            env.step(action)
            spent += time.perf_counter() - t0
            steps += 1
    return steps / spent


def measure_process(artifact_dir: Path) -> dict:
    """In a fresh interpreter: ``import assistive_compiler`` time (s), heavy modules it imported, and
    peak RSS (MB) of that process, which builds one env and steps it 200 times: its own high-water
    mark (``VmHWM``), never the caller's, which ``getrusage`` would carry over; None where the system
    has no ``/proc/self/status``."""
    child = subprocess.run(
        [sys.executable, "-c", _CHILD, str(artifact_dir)],
        capture_output=True,
        text=True,
        check=True,
        env=os.environ | {"PYTHONWARNINGS": "ignore"},
    )
    return json.loads(child.stdout.strip().splitlines()[-1])


def measure_steps_paired(
    envs: dict, steps: int, repeats: int, seed: int
) -> dict[str, tuple[list[float], list[float], list[float]]]:
    """:func:`measure_steps` of several envs, their repeats interleaved (repeat r of every env, then
    r + 1) so that a change of the machine's load falls on all of them alike; each repeat r is the
    same seeded episode with the same random actions in every env."""
    out: dict[str, tuple[list[float], list[float], list[float]]] = {k: ([], [], []) for k in envs}
    for r in range(repeats):
        for key, env in envs.items():
            for acc, values in zip(out[key], measure_steps(env, steps, 1, seed + r)):
                acc.extend(values)
    return out


BENCH_NOTES = (
    "vs_reference: our env steps/s on the reference harness's episodes over the reference's on them, "
    "its stored figure carried over to this machine's speed now by the machine probe (or a --reference-json "
    "figure measured beside ours as it is); at the reference's solver: that ratio times the reference-settings "
    "variant's speed over the shipped spec's on the paired episodes; "
    "env/raw: the same episodes, physics timed inside env.step (stepSimulation + gravity compensation) vs the whole step; "
    "reference_solver: the same episodes and actions on an artifact compiled with the reference's sim.solver, repeats "
    "interleaved with the shipped ones (when reference_solver_is_shipped, the same figure as env_steps_per_s); random actions; "
    "medians over repeats; physics_stages: each stage's share of stepSimulation by Bullet's profiler over one more "
    "episode of the first repeat's seed (the profiler's cost inflates every stage alike: read the shares); "
    "both agents acting: bench --coop; peak_rss_mb_one_env: the high-water mark (VmHWM) of a fresh process that "
    "imports the package, builds one env and steps it 200 times (none where /proc/self/status is absent)"
)
"""How to read :func:`bench`'s figures (its ``notes``)."""


def reference_rate(
    env_name: str,
    task: str,
    robot: str,
    probe_now: float,
    reference_json: dict[str, float] | None,
    reference_file: str | None,
) -> tuple[float | None, float | None, float | None, str | None]:
    """The reference's env steps/s to compare with, and where it comes from: (the stored figure,
    this machine's speed over the reference session's, the figure now, its source). From a
    ``--reference-json`` file measured beside ours (taken as it is), else the stored figure
    carried over to this machine's speed now (:func:`reference_now`); Nones where there is none."""
    if reference_json is not None:
        reference = reference_json.get(env_name)
        source = f"{reference_file}: measured beside ours with the reference harness" if reference is not None else None
        return None, None, reference, source
    carried = reference_now(task, robot, probe_now)
    return carried if carried is not None else (None, None, None, None)


def rate_at_reference_solver(
    rates: dict[str, tuple[list[float], list[float], list[float]]], env_med: float, reference_has_task: bool
) -> float | None:
    """Env steps/s at the reference's solver settings: the median measured on the variant's artifact
    (``rates["reference_solver"]``), or ``env_med`` (the shipped spec's) when the spec already uses
    them; None when the reference has no such task."""
    if "reference_solver" in rates:
        return statistics.median(rates["reference_solver"][0])
    return env_med if reference_has_task else None


def bench(
    spec: str,
    robot: str | None,
    steps: int,
    resets: int,
    repeats: int,
    seed: int = 0,
    reference_json: dict[str, float] | None = None,
    reference_file: str | None = None,
) -> dict:
    """Speed figures of one (task, robot), all taken in this one run (medians over repeats).

    Env steps/s is measured at the spec's solver settings and, where they differ, at the reference
    implementation's (:mod:`~assistive_compiler.spec.reference_solver`: an artifact compiled from
    an ``extends:`` variant), the same episodes and actions, repeats interleaved; each against the
    reference's measured rate, so no speed claim rests on simulating less. The ratio to the
    reference is taken on the reference harness's own episodes (:func:`measure_harness_protocol`),
    and a stored reference figure is first carried over to this machine's speed now
    (:func:`reference_now`, the :mod:`~assistive_compiler.machine_probe`)."""
    from ..compile.compiler import compile_task
    from ..machine_probe import probe_steps_per_s
    from ..runtime.env import AssistiveEnv
    from ..spec.load import load_spec
    from ..spec.reference_solver import reference_solver, solver_settings, write_reference_variant

    loaded = load_spec(spec).spec
    with tempfile.TemporaryDirectory() as tmp:
        cold = compile_task(spec, robot, Path(tmp) / "cold", force=True)
        cached = compile_task(spec, robot, Path(tmp) / "cold")
        assert cached.cache_hit
        envs = {"shipped": AssistiveEnv.from_compiled(cold)}
        variant = write_reference_variant(spec, loaded, Path(tmp) / "specs")
        if variant is not None:
            envs["reference_solver"] = AssistiveEnv.from_compiled(
                compile_task(variant, robot, Path(tmp) / "reference_solver")
            )
        rates = measure_steps_paired(envs, steps, repeats, seed)
        for extra in list(envs)[1:]:
            envs.pop(extra).close()
        env = envs["shipped"]
        env_rates, raw_rates, overhead = rates["shipped"]
        raw_loop = measure_raw_loop(env, steps)
        reset_ms, seeded_ms = measure_resets(env, resets)
        stages = measure_stages(env, steps, seed)
        m = env.manifest
        env_name = m.gym_id.rpartition("/")[2].removesuffix("-v1")
        probe_now = probe_steps_per_s()
        stored, speed, reference, reference_figure = reference_rate(
            env_name, m.task, m.robot_name, probe_now, reference_json, reference_file
        )
        # Only where there is a reference figure to divide by (Dressing's 400 steps alone take 10 s).
        harness_rate = measure_harness_protocol(env) if reference is not None else None
        env.close()
        proc = measure_process(cold.out_dir)
    env_med = statistics.median(env_rates)
    raw_med = statistics.median(raw_rates)
    reset_med, reset_p95 = _median_p95(reset_ms)
    ref_solver = reference_solver(m.task)
    at_ref = rate_at_reference_solver(rates, env_med, ref_solver is not None)
    return {
        "task": m.task,
        "robot": m.robot_name,
        "gym_id": m.gym_id,
        "obs_size": sum(t.size for t in m.observations["robot"]),
        "action_size": m.robot.action_size,
        "env_steps_per_s": round(env_med, 1),
        "env_steps_per_s_harness_episodes": round(harness_rate, 1) if harness_rate is not None else None,
        "reference_env_steps_per_s": round(reference, 1) if reference is not None else None,
        "reference_figure": reference_figure,
        "reference_env_steps_per_s_as_stored": stored,
        "machine_probe_steps_per_s": round(probe_now, 1),
        "machine_speed_vs_reference_session": round(speed, 3) if speed is not None else None,
        "vs_reference": round(harness_rate / reference, 2) if harness_rate and reference else None,
        "solver": solver_settings(loaded),
        "reference_solver": ref_solver,
        "reference_solver_is_shipped": ref_solver is not None and variant is None,
        "env_steps_per_s_reference_solver": round(at_ref, 1) if at_ref is not None else None,
        "vs_reference_at_reference_solver": round(harness_rate * (at_ref / env_med) / reference, 2)
        if at_ref is not None and harness_rate and reference
        else None,
        "raw_physics_steps_per_s": round(raw_med, 1),
        "env_over_raw": round(env_med / raw_med, 3),
        "env_overhead_us_per_step": round(statistics.median(overhead), 1),
        "raw_loop_steps_per_s_at_rest": round(raw_loop, 1),
        "physics_stages": stages,
        "reset_ms_median": round(reset_med, 3),
        "reset_ms_p95": round(reset_p95, 3),
        "resets": resets,
        "seeded_reset_ms_median": round(statistics.median(seeded_ms), 2),
        "compile_s_cold": round(cold.seconds, 3),
        "compile_s_cached": round(cached.seconds, 3),
        "import_s": round(proc["import_s"], 4),
        "heavy_modules_on_import": proc["heavy_modules_on_import"],
        "peak_rss_mb_one_env": round(proc["peak_rss_mb"], 1) if proc["peak_rss_mb"] is not None else None,
        "steps_per_repeat": steps,
        "repeats": repeats,
        "notes": BENCH_NOTES,
    }


BENCH_TABLE = (
    "task",
    "robot",
    "env_steps_per_s",
    "env_steps_per_s_reference_solver",
    "raw_physics_steps_per_s",
    "env_over_raw",
    "reset_ms_median",
    "env_steps_per_s_harness_episodes",
    "reference_env_steps_per_s",
    "machine_speed_vs_reference_session",
    "vs_reference",
    "vs_reference_at_reference_solver",
)
"""The columns of ``bench``'s table for several specs or robots."""

BENCH_COOP_TABLE = ("task", "robot", "single_agent_env_steps_per_s", "multi_agent_env_steps_per_s", "multi_over_single")
"""The columns of ``bench --coop``'s table for several specs."""


def bench_coop_spec(spec: str, robot: str | None, steps: int, repeats: int, seed: int) -> dict:
    """``bench --coop``: single- and multi-agent env steps/s of the spec's artifact in one run
    (:func:`assistive_compiler.coop.bench_coop`), compiled into a temporary directory."""
    from ..compile.compiler import compile_task
    from ..coop import bench_coop, check_coop_spec
    from ..spec.load import load_spec

    check_coop_spec(load_spec(spec))
    with tempfile.TemporaryDirectory() as tmp:
        return bench_coop(
            compile_task(spec, robot, Path(tmp) / "coop").out_dir, steps=steps, repeats=repeats, seed=seed
        )


def bench_robots(args: argparse.Namespace) -> list[str | None]:
    """The robots ``bench`` measures: every ``--robot`` and the names in ``--robots`` (comma-separated,
    as ``compare`` takes them), in order, each once; [None] (each spec's default robot) for none."""
    names = list(args.robot or []) + [r.strip() for r in (args.robots or "").split(",") if r.strip()]
    return list(dict.fromkeys(names)) or [None]


def cmd_bench(args: argparse.Namespace) -> int:
    from .output import cell, print_table, progress

    results = []
    pairs = [(spec, robot) for spec in args.specs for robot in bench_robots(args)]
    if args.training:
        from .bench_training import cmd_bench_training

        return cmd_bench_training(args, pairs)
    reference_json = load_reference_json(args.reference_json) if args.reference_json else None
    with progress("bench", len(pairs)) as tracker:
        for spec, robot in pairs:
            if args.coop:
                r = bench_coop_spec(spec, robot, args.steps, args.repeats, args.seed)
                tracker.done(
                    f"{r['name']}: {r['multi_agent_env_steps_per_s']} multi-agent env steps/s, "
                    f"{r['multi_over_single']} x single-agent ({spec})"
                )
            else:
                r = bench(
                    spec, robot, args.steps, args.resets, args.repeats, args.seed, reference_json, args.reference_json
                )
                tracker.done(f"{r['gym_id']}: {r['env_steps_per_s']} env steps/s ({spec})")
            results.append(r)
    if args.json:
        print(json.dumps(results[0] if len(results) == 1 else results, indent=1))
        return EXIT_OK
    if len(results) == 1:
        figures = {k: v for k, v in results[0].items() if k != "notes"}
        print_table(
            ["figure", "value"],
            [[key, _percent(value) if key == "physics_stages" else cell(value)] for key, value in figures.items()],
            left=["figure", "value"],
            caption=f"notes: {results[0]['notes']}",
        )
        return EXIT_OK
    # Several tasks or robots: one row per spec x robot (taken one after the other in this run; medians over repeats).
    columns = BENCH_COOP_TABLE if args.coop else BENCH_TABLE
    print_table(columns, [[cell(r[k]) for k in columns] for r in results], left=("task", "robot"))
    if not args.coop:
        stages = list(dict.fromkeys(stage for r in results for stage in r["physics_stages"]))
        print("\nwhere the physics goes (share of stepSimulation, Bullet's profiler):")
        print_table(
            ["task", "robot", *stages],
            [
                [r["task"], r["robot"], *(f"{100 * r['physics_stages'].get(k, 0.0):.0f}%" for k in stages)]
                for r in results
            ],
            left=("task", "robot"),
        )
        for figure in sorted({r["reference_figure"] for r in results if r["reference_figure"]}):
            rows = ", ".join(f"{r['task']}/{r['robot']}" for r in results if r["reference_figure"] == figure)
            print(f"reference_env_steps_per_s of {rows}: {figure}")
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser(
        "bench",
        help="speed figures taken in one run: steps/s vs raw physics and the reference, resets, compile, import, RSS",
    )
    add_library_argument(p)
    p.add_argument(
        "specs",
        nargs="+",
        metavar="spec",
        help="task spec file(s) or shipped task names (feeding); several print one row each",
    )
    p.add_argument(
        "--robot",
        action="append",
        help="robot (default: each spec's default); may be given several times: one row per spec x robot",
    )
    p.add_argument(
        "--robots",
        help="comma-separated robot names, e.g. jaco,stretch (as compare takes them); with --robot, both count",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the first repeat's episode and of the random actions")
    p.add_argument("--steps", type=int, default=400, help="env steps per repeat")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--resets", type=int, default=100)
    p.add_argument(
        "--coop",
        action="store_true",
        help="multi-agent (PettingZoo, both agents acting) vs single-agent env steps/s, in one run",
    )
    p.add_argument("--json", action="store_true")
    add_training_arguments(p)
    p.add_argument(
        "--reference-json",
        dest="reference_json",
        metavar="FILE",
        help="reference figures measured beside ours: the lines the reference harness's 'measure.py ag ENV' printed "
        "(default: the stored figures, each reported with the date and conditions it was measured under)",
    )
    p.set_defaults(func=cmd_bench)

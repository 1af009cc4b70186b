"""Where an env step's time goes, per task: our Python against ``stepSimulation``, and inside Bullet
which stages cost most (constraint solving, contact setup, collision detection, soft bodies), with a
census of the contact points each pair of bodies brings to the solver.

Usage::

    python benchmarks/physics_profile.py                 # the six shipped tasks on Jaco, Markdown
    python benchmarks/physics_profile.py specs/tasks/feeding.yaml --robot pr2 --steps 200 --json

Method. One episode of seeded random actions per task (the same seed for every task). The step
time and the physics time inside it are taken as ``bench`` takes them (the env's ``physics_s``,
the physics timed inside ``env.step``). Bullet's own profiler (``STATE_LOGGING_PROFILE_TIMINGS``, the timings
the engine records around its stages) runs over the same steps, and its intervals are nested by
time to give each stage's share of ``stepSimulation``. The profiler's own cost inflates the
stage times a little, evenly, so the shares, not the absolute times, are what to read; the
step/physics split is measured without it, in a second pass over the same episode. After every
env step the contact points of the last physics step are counted by body pair (what the solver
sets up rows for: one normal and two friction rows per point).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.paths import specs_dir
from assistive_compiler.profiling import STAGES, profile_episode
from assistive_compiler.runtime.env import AssistiveEnv

TASKS = ["feeding", "scratch_itch", "drinking", "bed_bathing", "arm_manipulation", "dressing"]


def profile(spec: Path, robot: str, steps: int, seed: int, out_dir: Path) -> dict:
    """The figures of one (task, robot): see the module docstring."""
    result = compile_task(spec, robot, out_dir / f"{spec.stem}-{robot}")
    env = AssistiveEnv.from_compiled(result)
    try:
        env.action_space.seed(seed)
        actions = [env.action_space.sample() for _ in range(steps)]
        # Pass 1, no profiler: the step and the physics inside it.
        env.reset(seed=seed)
        physics0 = env.physics_s
        t0 = time.perf_counter()
        for a in actions:
            env.step(a)
        total = time.perf_counter() - t0
        physics = [env.physics_s - physics0]
        # Pass 2, the same episode under Bullet's profiler, counting contacts.
        shares, contacts = profile_episode(env, actions, seed)
        return {
            "task": env.manifest.task,
            "robot": robot,
            "steps": steps,
            "solver": {"sub_steps": env.manifest.sim.sub_steps, "iterations": env.manifest.sim.solver_iterations},
            "env_steps_per_s": steps / total,
            "physics_share_of_step": physics[0] / total,
            "python_us_per_step": (total - physics[0]) / steps * 1e6,
            "bullet_stage_shares": shares,
            "contact_points_per_env_step": contacts,
        }
    finally:
        env.close()


def markdown(rows: list[dict]) -> str:
    stages = list(STAGES) + ["other"]
    head = "| task | env steps/s | physics share | Python µs/step | " + " | ".join(stages) + " |"
    lines = [head, "|" + "---|" * (4 + len(stages))]
    for r in rows:
        s = r["bullet_stage_shares"]
        lines.append(
            f"| {r['task']} | {r['env_steps_per_s']:.0f} | {100 * r['physics_share_of_step']:.0f}% | "
            f"{r['python_us_per_step']:.0f} | " + " | ".join(f"{100 * s.get(k, 0):.0f}%" for k in stages) + " |"
        )
    lines += ["", "Contact points at the end of each env step (the last physics step's), by body pair:", ""]
    for r in rows:
        top = list(r["contact_points_per_env_step"].items())[:6]
        lines.append(f"- {r['task']}: " + ("; ".join(f"{pair} {n:.1f}" for pair, n in top) or "none"))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("specs", nargs="*", help="task specs (default: the six shipped tasks)")
    p.add_argument("--robot", default="jaco")
    p.add_argument("--steps", type=int, default=200, help="env steps (one episode of random actions)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    specs = [Path(s) for s in args.specs] or [specs_dir() / "tasks" / f"{t}.yaml" for t in TASKS]
    with tempfile.TemporaryDirectory() as tmp:
        rows = [profile(spec, args.robot, args.steps, args.seed, Path(tmp)) for spec in specs]
    print(json.dumps(rows, indent=1) if args.json else markdown(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())

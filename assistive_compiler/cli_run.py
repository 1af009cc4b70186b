"""The runtime commands of the CLI: ``run``, ``render``, ``bench`` and ``demo``.

Each compiles the spec first (a cache hit when nothing changed), so a spec path is all they need.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from .episode import EpisodeTally
from .policies import HUMAN_POLICIES, POLICIES


def _env(spec: str, robot: str | None, out: str | None = None, **kwargs):
    from .runtime.env import AssistiveEnv

    return AssistiveEnv.from_spec(spec, robot=robot, out_dir=out, **kwargs)


# --------------------------------------------------------------------------------------------
# run


def rollout(env, policy, seed: int) -> dict:
    """One episode: return, success, each term's unweighted values summed over the episode (the
    reward is Σ weight × value: see ``term_weights`` in ``run --json``), mean force on the person (N)."""
    obs, info = env.reset(seed=seed)
    tally = EpisodeTally()
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        tally.add(reward, info)
        done = terminated or truncated
    return tally.summary(seed)


def cmd_run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from .policies import make_policy

    if args.coop:  # both agents act (co-optimisation); the person by --human-policy
        from .coop import parallel_env, rollout_coop

        coop_env = parallel_env(args.spec, args.robot, out_dir=args.out)
        env, label = coop_env.env, f"{args.policy}, human {args.human_policy}"

        def play(seed: int) -> dict:
            return rollout_coop(coop_env, args.policy, args.human_policy, seed)
    else:
        env, label = _env(args.spec, args.robot, args.out), args.policy
        policy = make_policy(args.policy, env, seed=args.seed)

        def play(seed: int) -> dict:
            return rollout(env, policy, seed)
    weights = {t.name: t.weight for t in env.manifest.reward}
    episodes = []
    bar = tqdm(range(args.episodes), desc=f"{env.manifest.gym_id} {label}", unit="ep", file=sys.stderr, disable=args.quiet)
    for k in bar:
        episodes.append(play(args.seed + k))
        bar.set_postfix(success=f"{sum(e['success'] for e in episodes)}/{len(episodes)}")
    env.close()
    rate = sum(e["success"] for e in episodes) / len(episodes)
    if args.json:
        print(json.dumps({"task": env.manifest.task, "robot": env.manifest.robot_name, "policy": args.policy,
                          **({"human_policy": args.human_policy} if args.coop else {}),
                          "term_weights": weights, "episodes": episodes, "success_rate": rate,
                          "mean_return": float(np.mean([e["return"] for e in episodes]))}, indent=1))
        return 0
    print(f"{env.manifest.gym_id}  policy={args.policy}{f'  human-policy={args.human_policy}' if args.coop else ''}  episodes={len(episodes)}  seed={args.seed}")
    print(f"{'ep':>3} {'seed':>5} {'return':>9} {'success':>7}  largest weighted terms (episode sums)")
    for k, e in enumerate(episodes):
        top = sorted(e["terms"].items(), key=lambda kv: -abs(weights[kv[0]] * kv[1]))[:3]
        shown = ", ".join(f"{name} {weights[name] * value:+.1f}" for name, value in top)
        print(f"{k:>3} {e['seed']:>5} {e['return']:>9.1f} {'yes' if e['success'] else 'no':>7}  {shown}")
    print(f"success rate {rate:.2f}   mean return {np.mean([e['return'] for e in episodes]):.1f}")
    return 0


# --------------------------------------------------------------------------------------------
# render


def record(env, policy, seed: int, every: int) -> tuple[list[np.ndarray], dict]:
    """Frames of one episode (every ``every`` steps, plus the first and last) and its summary."""
    obs, _ = env.reset(seed=seed)
    frames, total, done, info = [env.render()], 0.0, False, {}
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total += reward
        done = terminated or truncated
        if env.steps % every == 0 or done:
            frames.append(env.render())
    return frames, {"return": total, "success": bool(info.get("task_success")), "steps": env.steps}


MONTAGE_AT = (0.0, 0.1, 0.25, 1.0)
"""Where in an episode the PNG strip's frames are taken: the start, the approach (most motion in
these tasks happens early), and the end."""


def montage(frames: list[np.ndarray], at: tuple[float, ...] = MONTAGE_AT) -> np.ndarray:
    """Frames at fractions ``at`` of the episode, side by side: the episode at a glance."""
    idx = [round(f * (len(frames) - 1)) for f in at]
    return np.concatenate([frames[i] for i in idx], axis=1)


def write_picture(frames: list[np.ndarray], out: Path, fps: int) -> None:
    from PIL import Image

    out.parent.mkdir(parents=True, exist_ok=True)
    if out.suffix.lower() == ".gif":
        images = [Image.fromarray(f) for f in frames]
        images[0].save(out, save_all=True, append_images=images[1:], duration=int(1000 / fps), loop=0, optimize=False)
    elif out.suffix.lower() == ".png":
        Image.fromarray(montage(frames)).save(out)
    else:
        raise SystemExit(f"--out must end in .gif or .png, got {out}")


def cmd_render(args: argparse.Namespace) -> int:
    from .policies import make_policy

    env = _env(args.spec, args.robot, args.out_dir, render_mode="rgb_array", render_size=(args.width, args.height))
    policy = make_policy(args.policy, env, seed=args.seed)
    frames, summary = record(env, policy, args.seed, args.every)
    env.close()
    write_picture(frames, Path(args.out), fps=max(1, 10 // args.every))
    print(f"wrote {args.out} ({len(frames)} frames; return {summary['return']:.1f}, success {'yes' if summary['success'] else 'no'})")
    return 0


# --------------------------------------------------------------------------------------------
# bench


def _median_p95(values: list[float]) -> tuple[float, float]:
    s = sorted(values)
    return statistics.median(s), s[min(len(s) - 1, int(round(0.95 * (len(s) - 1))))]


_CHILD = r"""
import json, resource, sys, time, numpy as np
t = time.perf_counter()
import assistive_compiler
import_s = time.perf_counter() - t
heavy = sorted(m for m in ("torch", "tensorflow", "jax", "ray", "stable_baselines3", "pybullet") if m in sys.modules)
from assistive_compiler.runtime.env import AssistiveEnv
env = AssistiveEnv(sys.argv[1])
env.reset(seed=0)
for _ in range(200):
    env.step(env.action_space.sample())
print(json.dumps({"import_s": import_s, "heavy_modules_on_import": heavy,
                  "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


#: Env steps/s of the reference implementation (Assistive Gym v1.0 on stock pybullet, random actions,
#: 200-step episodes, one process, a 2-core shared machine like ours), per (task, robot) it was
#: measured for: shared/reference/performance-anchors.md. Dressing does not run on stock pybullet.
REFERENCE_STEPS_PER_S = {
    ("scratch_itch", "jaco"): 423, ("scratch_itch", "pr2"): 188, ("scratch_itch", "sawyer"): 428, ("scratch_itch", "baxter"): 312,
    ("bed_bathing", "jaco"): 156,
    ("feeding", "jaco"): 248, ("feeding", "pr2"): 135, ("feeding", "sawyer"): 237, ("feeding", "baxter"): 199,
    ("drinking", "jaco"): 37,
    ("arm_manipulation", "jaco"): 216,
}


def bench(spec: str, robot: str | None, steps: int, resets: int, repeats: int, seed: int = 0) -> dict:
    """Speed figures of one (task, robot), all taken in this one run (medians over repeats)."""
    import tempfile

    import pybullet as pb

    from .compile.compiler import compile_task

    with tempfile.TemporaryDirectory() as tmp:
        cold = compile_task(spec, robot, Path(tmp) / "cold", force=True)
        cached = compile_task(spec, robot, Path(tmp) / "cold")
        assert cached.cache_hit
        from .runtime.env import AssistiveEnv

        env = AssistiveEnv(cold.out_dir)
        # Time physics inside the env's own steps: the same scene, the same motion.
        physics = [0.0]
        world = env.world
        original = world.step_physics

        def timed() -> None:
            t0 = time.perf_counter()
            original()
            physics[0] += time.perf_counter() - t0

        world.step_physics = timed  # type: ignore[method-assign]
        env.action_space.seed(seed)
        env_rates, raw_rates, overhead = [], [], []
        for r in range(repeats):
            env.reset(seed=seed + r)
            physics[0] = 0.0
            t0 = time.perf_counter()
            for _ in range(steps):
                env.step(env.action_space.sample())
            total = time.perf_counter() - t0
            env_rates.append(steps / total)
            raw_rates.append(steps / physics[0])
            overhead.append((total - physics[0]) / steps * 1e6)
        # Both agents acting (co-optimisation, step_agents), where the person has policy joints.
        coop_rates = []
        if env.human_action_space is not None:
            env.human_action_space.seed(seed)
            for r in range(repeats):
                env.reset(seed=seed + r)
                t0 = time.perf_counter()
                for _ in range(steps):
                    env.step_agents(env.action_space.sample(), env.human_action_space.sample())
                coop_rates.append(steps / (time.perf_counter() - t0))
        # A raw loop of stepSimulation with nothing else, for reference.
        env.reset(seed=0)
        t0 = time.perf_counter()
        for _ in range(steps * env.manifest.sim.frame_skip):
            pb.stepSimulation(physicsClientId=world.client)
        raw_loop = steps / (time.perf_counter() - t0)
        reset_ms, seeded_ms = [], []
        for k in range(resets):  # unseeded: restore the saved state (the training path)
            env.step(env.action_space.sample())
            t0 = time.perf_counter()
            env.reset()
            reset_ms.append((time.perf_counter() - t0) * 1e3)
        for k in range(min(resets, 20)):  # seeded after stepping: rebuild for bit-exact replay
            env.step(env.action_space.sample())
            t0 = time.perf_counter()
            env.reset(seed=1000 + k)
            seeded_ms.append((time.perf_counter() - t0) * 1e3)
        m = env.manifest
        env.close()
        child = subprocess.run([sys.executable, "-c", _CHILD, str(cold.out_dir)], capture_output=True, text=True, check=True,
                               env=os.environ | {"PYTHONWARNINGS": "ignore"})
        proc = json.loads(child.stdout.strip().splitlines()[-1])
    env_med = statistics.median(env_rates)
    raw_med = statistics.median(raw_rates)
    reset_med, reset_p95 = _median_p95(reset_ms)
    return {
        "task": m.task, "robot": m.robot_name, "gym_id": m.gym_id,
        "obs_size": sum(t.size for t in m.observations["robot"]), "action_size": m.robot.action_size,
        "env_steps_per_s": round(env_med, 1),
        "reference_env_steps_per_s": REFERENCE_STEPS_PER_S.get((m.task, m.robot_name)),
        "vs_reference": round(env_med / REFERENCE_STEPS_PER_S[(m.task, m.robot_name)], 2) if (m.task, m.robot_name) in REFERENCE_STEPS_PER_S else None,
        "raw_physics_steps_per_s": round(raw_med, 1),
        "env_over_raw": round(env_med / raw_med, 3),
        "env_overhead_us_per_step": round(statistics.median(overhead), 1),
        "coop_env_steps_per_s": round(statistics.median(coop_rates), 1) if coop_rates else None,
        "raw_loop_steps_per_s_at_rest": round(raw_loop, 1),
        "reset_ms_median": round(reset_med, 3), "reset_ms_p95": round(reset_p95, 3), "resets": resets,
        "seeded_reset_ms_median": round(statistics.median(seeded_ms), 2),
        "compile_s_cold": round(cold.seconds, 3), "compile_s_cached": round(cached.seconds, 3),
        "import_s": round(proc["import_s"], 4), "heavy_modules_on_import": proc["heavy_modules_on_import"],
        "peak_rss_mb_one_env": round(proc["peak_rss_mb"], 1),
        "steps_per_repeat": steps, "repeats": repeats,
        "notes": "env/raw: the same episodes, physics timed inside env.step (stepSimulation + gravity compensation) vs the whole step; random actions; coop: step_agents with both agents acting (None: the person has no policy joints); medians over repeats",
    }


_BENCH_COOP_TABLE = ("task", "robot", "single_agent_env_steps_per_s", "multi_agent_env_steps_per_s", "multi_over_single")
_BENCH_TABLE = ("task", "robot", "env_steps_per_s", "raw_physics_steps_per_s", "reset_ms_median", "reference_env_steps_per_s", "vs_reference")


def bench_coop_spec(spec: str, robot: str | None, steps: int, repeats: int, seed: int) -> dict:
    """``bench --coop``: single- and multi-agent env steps/s of the spec's artifact in one run
    (:func:`assistive_compiler.coop.bench_coop`), compiled into a temporary directory."""
    import tempfile

    from .compile.compiler import compile_task
    from .coop import bench_coop, check_coop_spec
    from .spec.load import load_spec

    check_coop_spec(load_spec(spec))
    with tempfile.TemporaryDirectory() as tmp:
        return bench_coop(compile_task(spec, robot, Path(tmp) / "coop").out_dir, steps=steps, repeats=repeats, seed=seed)


def cmd_bench(args: argparse.Namespace) -> int:
    if args.coop:
        results = [bench_coop_spec(spec, args.robot, args.steps, args.repeats, args.seed) for spec in args.specs]
    else:
        results = [bench(spec, args.robot, args.steps, args.resets, args.repeats, args.seed) for spec in args.specs]
    if args.json:
        print(json.dumps(results[0] if len(results) == 1 else results, indent=1))
        return 0
    if len(results) == 1:
        width = max(len(k) for k in results[0])
        for key, value in results[0].items():
            print(f"{key:<{width}}  {value}")
        return 0
    # Several tasks: one row each (taken one after the other in this run; medians over repeats).
    columns = _BENCH_COOP_TABLE if args.coop else _BENCH_TABLE
    rows = [list(columns)] + [["-" if r[k] is None else str(r[k]) for k in columns] for r in results]
    widths = [max(len(row[i]) for row in rows) for i in range(len(columns))]
    for row in rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
    return 0


# --------------------------------------------------------------------------------------------
# render-person: the person variants a spec declares, side by side


def render_people(artifact_dir: Path, width: int = 360, height: int = 480) -> np.ndarray:
    """One frontal picture per person variant of an artifact (in the task's posture, on its seat),
    side by side and labelled with name, sex, mass and standing height."""
    import pybullet as pb
    from PIL import Image, ImageDraw

    from .runtime.world import PARK, World

    world = World(artifact_dir)
    m, c = world.m, world.client
    world.set_base_frame(world.robot, (PARK[0], PARK[1] - 20, PARK[2]), (0, 0, 0, 1))  # the robot is not the subject
    for att in m.tools:
        world.set_base_frame(world.bodies[att.body], (PARK[0], PARK[1] - 25, PARK[2]), (0, 0, 0, 1))
    seat_xy = np.asarray(m.body(m.person.variants[0].body).position[:2])
    for k, body in enumerate(b for b in m.bodies if b.kind == "furniture"):
        if np.linalg.norm(np.asarray(body.position[:2]) - seat_xy) > 0.5:  # keep only what they sit on
            world.set_base_frame(world.bodies[body.name], (PARK[0], PARK[1] - 30 - 5 * k, PARK[2]), body.orientation)
    panels = []
    for i, variant in enumerate(m.person.variants):
        for j, other in enumerate(m.person.variants):
            body = m.body(other.body)
            away = (PARK[0] + 10.0 * j, PARK[1], PARK[2])
            world.set_base_frame(world.variant_bodies[other.name], body.position if j == i else away, body.orientation)
        pos = np.asarray(m.body(variant.body).position)
        target = pos + [0.0, 0.0, -0.3]
        eye = target + [0.0, -2.6, 0.35]  # in front of the person, who faces -Y
        view = pb.computeViewMatrix(eye.tolist(), target.tolist(), [0, 0, 1], physicsClientId=c)
        proj = pb.computeProjectionMatrixFOV(40, width / height, 0.05, 10, physicsClientId=c)
        rgba = pb.getCameraImage(width, height, view, proj, renderer=pb.ER_TINY_RENDERER, lightDirection=[1, -2, 2], physicsClientId=c)[2]
        image = Image.fromarray(np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3])
        label = f"{variant.name}\n{variant.sex}, {variant.mass_kg:.1f} kg, {variant.standing_height_m:.3f} m"
        ImageDraw.Draw(image).multiline_text((8, 8), label, fill=(0, 0, 0))
        panels.append(np.asarray(image))
    world.close()
    return np.concatenate(panels, axis=1)


def cmd_render_person(args: argparse.Namespace) -> int:
    from PIL import Image

    from .compile.compiler import compile_task

    result = compile_task(args.spec, args.robot, args.out_dir)
    picture = render_people(result.out_dir)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(picture).save(args.out)
    names = ", ".join(v.name for v in result.manifest.person.variants)
    print(f"wrote {args.out} ({names})")
    return 0


# --------------------------------------------------------------------------------------------
# compare: one task, several robots


def compare(spec: str, robots: list[str], episodes: int, seed: int, out_root: str | None) -> list[dict]:
    """Per robot: placement quality, compile time and the scripted policy's results."""
    from .compile.compiler import compile_task
    from .errors import SpecError
    from .policies import make_policy
    from .runtime.env import AssistiveEnv

    rows = []
    for robot in robots:
        row: dict = {"robot": robot}
        out = Path(out_root) / robot if out_root else None
        try:
            result = compile_task(spec, robot, out, force=True)
        except SpecError as exc:
            row["error"] = "; ".join(p.message for p in exc.problems)
            rows.append(row)
            continue
        m = result.manifest
        row["compile_s"] = round(result.seconds, 2)
        placements = list(m.robot.placement.values())
        if all("mounted_on" in p for p in placements):
            row["placement"] = f"mounted on {placements[0]['mounted_on']}"
        else:
            best = [p["base_poses"][0] for p in placements]
            row["placement"] = "base search"
            row["goals_reached"] = f"{min(b['goals_reached'] for b in best)}/{best[0]['goals']}"
            row["jlwki"] = round(float(np.mean([b["jlwki"] for b in best])), 3)
        env = AssistiveEnv(result.out_dir)
        if m.scripted is not None:
            policy = make_policy("scripted", env)
            runs = [rollout(env, policy, seed + k) for k in range(episodes)]
            row["scripted_success"] = sum(r["success"] for r in runs) / len(runs)
            row["scripted_return"] = round(float(np.mean([r["return"] for r in runs])), 1)
        env.close()
        rows.append(row)
    return rows


def cmd_compare(args: argparse.Namespace) -> int:
    rows = compare(args.spec, [r.strip() for r in args.robots.split(",") if r.strip()], args.episodes, args.seed, args.out)
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    cols = ["robot", "placement", "goals_reached", "jlwki", "compile_s", "scripted_success", "scripted_return"]
    print(f"{args.spec}: {args.episodes} scripted episodes per robot from seed {args.seed}")
    print("  ".join(f"{c:>16}" for c in cols))
    for row in rows:
        if "error" in row:
            print(f"{row['robot']:>16}  failed to compile: {row['error']}")
            continue
        print("  ".join(f"{str(row.get(c, '-')):>16}" for c in cols))
    return 0


# --------------------------------------------------------------------------------------------
# demo: the README's main job


def cmd_demo(args: argparse.Namespace) -> int:
    from .compile.compiler import compile_task
    from .policies import make_policy
    from .runtime.env import AssistiveEnv

    spec = str(Path(args.spec))
    result = compile_task(spec, args.robot)
    m = result.manifest
    print(f"{'cache hit' if result.cache_hit else 'compiled'}: {m.task} for {m.robot_name} -> {result.out_dir}/ ({result.seconds:.2f} s)")
    env = AssistiveEnv(result.out_dir, render_mode="rgb_array")
    policy = make_policy("scripted", env)
    outcomes = []
    for k in range(args.episodes):
        frames = None
        if k == 0:
            frames, _ = record(env, policy, args.seed, every=10)
            env.reset(seed=args.seed)
        e = rollout(env, policy, args.seed + k)
        outcomes.append(e)
        eaten = e["success_metric"]
        print(f"episode {k}: return {e['return']:7.1f}  success {'yes' if e['success'] else 'no '}  "
              f"{m.success.term} {eaten:g} (need {m.success.threshold:g})  mean force on person {e['mean_force_on_human_n']:.2f} N")
        if frames is not None:
            write_picture(frames, Path(args.picture), fps=1)
    env.close()
    rate = sum(o["success"] for o in outcomes) / len(outcomes)
    print(f"scripted success {rate:.0%} over {len(outcomes)} episodes; picture: {args.picture}")
    return 0


def add_commands(sub) -> None:
    def common(p, policy: bool = True):
        p.add_argument("spec", help="task spec file")
        p.add_argument("--robot", help="robot (default: the spec's default)")
        if policy:
            p.add_argument("--policy", choices=POLICIES, default="scripted", help="policy to roll out (default scripted)")
        p.add_argument("--seed", type=int, default=0, help="first episode seed")

    p = sub.add_parser("run", help="roll out a policy and report returns, success and the largest terms")
    common(p)
    p.add_argument("--episodes", type=int, default=5)
    p.add_argument("--out", help="artifact directory (default generated/<task>-<robot>)")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--coop", action="store_true", help="co-optimisation: the person acts too (by --human-policy), shared reward")
    p.add_argument("--human-policy", dest="human_policy", choices=HUMAN_POLICIES, default="random",
                   help="with --coop: random, zero (keep still by acting) or hold (no human action: the static person); default random")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("render", help="write a GIF (or a PNG strip) of one episode, headless")
    common(p)
    p.add_argument("--out", required=True, help="output .gif or .png")
    p.add_argument("--every", type=int, default=4, help="record every N steps (default 4)")
    p.add_argument("--width", type=int, default=480)
    p.add_argument("--height", type=int, default=360)
    p.add_argument("--out-dir", dest="out_dir", help="artifact directory")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("bench", help="speed figures taken in one run: steps/s vs raw physics and the reference, resets, compile, import, RSS")
    p.add_argument("specs", nargs="+", metavar="spec", help="task spec file(s); several print one row each")
    p.add_argument("--robot", help="robot (default: each spec's default)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first repeat's episode and of the random actions")
    p.add_argument("--steps", type=int, default=400, help="env steps per repeat")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--resets", type=int, default=100)
    p.add_argument("--coop", action="store_true", help="multi-agent (PettingZoo, both agents acting) vs single-agent env steps/s, in one run")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_bench)

    p = sub.add_parser("render-person", help="draw the person variants a spec declares, side by side (PNG)")
    p.add_argument("spec", help="task spec file")
    p.add_argument("--robot", help="robot to compile the task for (default: the spec's default)")
    p.add_argument("--out", required=True, help="output .png")
    p.add_argument("--out-dir", dest="out_dir", help="artifact directory")
    p.set_defaults(func=cmd_render_person)

    p = sub.add_parser("compare", help="compile a task for several robots and compare placement and scripted results")
    p.add_argument("spec", help="task spec file")
    p.add_argument("--robots", required=True, help="comma-separated robot names, e.g. pr2,jaco,baxter,sawyer,panda")
    p.add_argument("--episodes", type=int, default=10, help="scripted episodes per robot")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", help="artifact root (default generated/<task>-<robot>)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("demo", help="the main job: compile Feeding for Jaco, run the scripted policy, write a picture")
    p.add_argument("--spec", default=str(_default_feeding()), help="task spec (default: the shipped feeding.yaml)")
    p.add_argument("--robot", default="jaco")
    p.add_argument("--episodes", type=int, default=3)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--picture", default="feeding.png", help="picture of the first episode (.png strip or .gif)")
    p.set_defaults(func=cmd_demo)


def _default_feeding() -> Path:
    from .paths import specs_dir, display

    return Path(display(specs_dir() / "tasks" / "feeding.yaml"))

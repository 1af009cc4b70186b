"""Do the shipped solver settings change a task's outcome? Shipped vs the reference's, scripted policy.

For one task × robot this compiles the shipped spec and a variant at the reference implementation's
solver settings (:mod:`assistive_compiler.spec.reference_solver`: a spec that ``extends:`` the
shipped one and overrides ``sim.solver``), runs the scripted policy for the same N seeds on both,
and reports per setting (per-episode figures, then mean ± sd over the seeds):

* success rate, return, the success metric;
* contact force on the person (N): per episode the mean and the 95th percentile of the per-step
  Σ normal force of robot, tools and garments on the person (``info["total_force_on_human"]``,
  the preference costs' input);
* penetration (mm): per episode the deepest contact (``contactDistance`` < 0 of
  ``getContactPoints``, sampled after each env step, i.e. the last physics step's manifold) of the
  robot, tools and particles into the person and the furniture;
* particles lost and consumed per episode (the particle system's events);
* held-joint drift (rad): per episode max |q − q_hold| over the person's stiffly held joints and,
  separately, over its compliantly held (limp, yielding) ones — tremoring joints left out — and
  over the robot's movable joints outside the action (none for most robots: welded at compile
  time); a kind of joint a task does not have is left out of its table;
* env steps/s: the episodes' ``env.step`` time (the policy's IK excluded; noisy on a shared machine).

With ``--without-rest`` the compared variant is instead the shipped spec with every particle set's
``rest`` switched off (``rest: null`` in a spec that ``extends:`` it: the particles are simulated
every step), at the shipped solver settings: does carrying resting particles change the outcome?

With ``--against-artifact DIR`` the compared variant is an artifact of the same task and robot
compiled elsewhere, e.g. by the commit before a compiler change (check out that commit and
``compile`` the spec into DIR): does the change keep the physics outcomes?

Verdict per metric: the episodes are paired by seed, so the difference (reference − shipped) of
the per-seed values is bootstrapped (2000 resamples); "within noise" when its 95% interval holds
0, else "differs". Run e.g.::

    .venv/bin/python benchmarks/physics_settings.py specs/tasks/feeding.yaml --robot jaco --seeds 20 \\
        --json out/feeding.json --markdown out/feeding.md
    .venv/bin/python benchmarks/physics_settings.py specs/tasks/drinking.yaml --robot jaco --without-rest
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pybullet as pb

from assistive_compiler.artifact import Manifest
from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.policies.scripted import ScriptedPolicy
from assistive_compiler.runtime.env import AssistiveEnv
from assistive_compiler.spec.load import load_spec
from assistive_compiler.spec.reference_solver import reference_solver, solver_settings, write_solver_variant

#: (key, label, unit) of the per-episode figures compared, in table order.
METRICS = (
    ("success", "success rate", ""),
    ("return", "return", ""),
    ("success_metric", "success metric", ""),
    ("force_mean_n", "force on person, mean", "N"),
    ("force_p95_n", "force on person, p95", "N"),
    ("penetration_mm", "max penetration (robot/tool/particles)", "mm"),
    ("particles_lost", "particles lost", ""),
    ("particles_consumed", "particles consumed", ""),
    ("person_stiff_drift_rad", "person stiffly held joints' drift, max", "rad"),
    ("person_compliant_drift_rad", "person compliantly held joints' drift, max", "rad"),
    ("robot_idle_drift_rad", "robot idle-joint drift, max", "rad"),
    ("steps_per_s", "env steps/s (policy excluded)", "1/s"),
)


class EpisodeProbe:
    """Per-step measurements of one episode beyond the env's info."""

    def __init__(self, env: AssistiveEnv):
        self.env = env
        m, c = env.manifest, env.client
        self.robot = env.body_id("robot")
        self.intruders = [self.robot] + [env.body_id(b.name) for b in m.bodies if b.kind == "tool"]
        self.intruders += [pid for ps in m.particles for pid in env.particle_ids(ps.name)]
        self.furniture = {env.body_id(b.name) for b in m.bodies if b.kind == "furniture"}
        movable = [
            j
            for j in range(pb.getNumJoints(self.robot, physicsClientId=c))
            if pb.getJointInfo(self.robot, j, physicsClientId=c)[2] != pb.JOINT_FIXED
        ]
        self.robot_idle = [j for j in movable if j not in set(env.arm_idx)]

    def begin(self) -> None:
        env, c = self.env, self.env.client
        h = env.human
        compliant = set(env.manifest.person.compliant_joints)
        tremor = {k for k, _ in h._tremor}
        variant = next(v for v in env.manifest.person.variants if v.name == env.person_variant)
        self.person_id = h.body_id
        self.held = {}  # kind → (joint indices, hold angles)
        for kind, soft in (("stiff", False), ("compliant", True)):
            keep = [k for k, j in enumerate(variant.movable_joints) if (j in compliant) == soft and k not in tremor]
            if keep:
                self.held[kind] = ([h.idx[k] for k in keep], np.array([h.hold[k] for k in keep]))
        self.idle_q = (
            np.array([s[0] for s in pb.getJointStates(self.robot, self.robot_idle, physicsClientId=c)])
            if self.robot_idle
            else None
        )
        self.targets = self.furniture | {self.person_id}
        self.forces, self.depth, self.idle_drift = [], 0.0, 0.0
        self.hold_drift = {kind: 0.0 for kind in self.held}
        self.lost = self.consumed = 0

    def after_step(self, info: dict) -> None:
        env, c = self.env, self.env.client
        self.forces.append(info["total_force_on_human"])
        targets = self.targets
        for a in self.intruders:
            for cp in pb.getContactPoints(bodyA=a, physicsClientId=c):
                if cp[2] in targets and cp[8] < 0:
                    self.depth = max(self.depth, -cp[8])
        for ps in env.manifest.particles:  # (snap.events also holds the markers' counts)
            ev = env.snap.events[ps.name]
            self.lost += ev.lost
            self.consumed += ev.consumed
        for kind, (idx, hold) in self.held.items():
            q = np.array([s[0] for s in pb.getJointStates(self.person_id, idx, physicsClientId=c)])
            self.hold_drift[kind] = max(self.hold_drift[kind], float(np.max(np.abs(q - hold))))
        if self.idle_q is not None:
            q = np.array([s[0] for s in pb.getJointStates(self.robot, self.robot_idle, physicsClientId=c)])
            self.idle_drift = max(self.idle_drift, float(np.max(np.abs(q - self.idle_q))))


def run_episodes(artifact: Path, seeds: list[int]) -> list[dict]:
    """The scripted policy's episodes for ``seeds`` on ``artifact``: one dict of figures each."""
    env = AssistiveEnv(artifact)
    policy = ScriptedPolicy(env)
    probe = EpisodeProbe(env)
    out = []
    for seed in seeds:
        obs, info = env.reset(seed=seed)
        probe.begin()
        total, stepping, done = 0.0, 0.0, False
        while not done:
            action = policy(obs)
            t0 = time.perf_counter()
            obs, reward, terminated, truncated, info = env.step(action)
            stepping += time.perf_counter() - t0
            total += reward
            probe.after_step(info)
            done = terminated or truncated
        out.append(
            {
                "seed": seed,
                "success": float(info["task_success"]),
                "return": total,
                "success_metric": float(info["success_metric"]),
                "force_mean_n": float(np.mean(probe.forces)),
                "force_p95_n": float(np.percentile(probe.forces, 95)),
                "penetration_mm": probe.depth * 1e3,
                "particles_lost": float(probe.lost),
                "particles_consumed": float(probe.consumed),
                "person_stiff_drift_rad": probe.hold_drift.get("stiff"),
                "person_compliant_drift_rad": probe.hold_drift.get("compliant"),
                "robot_idle_drift_rad": probe.idle_drift if probe.robot_idle else None,
                "steps_per_s": env.steps / stepping,
            }
        )
    env.close()
    return out


def paired_ci(a: list[float], b: list[float], resamples: int = 2000, seed: int = 0) -> tuple[float, float, float]:
    """Mean of b − a over paired seeds and its bootstrap 95% interval."""
    d = np.asarray(b, dtype=float) - np.asarray(a, dtype=float)
    rng = np.random.default_rng(seed)
    means = d[rng.integers(len(d), size=(resamples, len(d)))].mean(axis=1)
    return float(d.mean()), float(np.percentile(means, 2.5)), float(np.percentile(means, 97.5))


def compare(shipped: list[dict], reference: list[dict]) -> list[dict]:
    """One row per metric: mean ± sd per setting, the paired difference and its interval, the verdict.
    Only seeds where both settings have the figure count (e.g. an episode whose person tremors in
    every held joint has no held-joint drift); a metric no seed has is left out."""
    rows = []
    for key, label, unit in METRICS:
        pairs = [(x[key], y[key]) for x, y in zip(shipped, reference) if x[key] is not None and y[key] is not None]
        if not pairs:
            continue
        a, b = (list(v) for v in zip(*pairs))
        diff, lo, hi = paired_ci(a, b)
        noise = lo <= 0.0 <= hi
        rows.append(
            {
                "metric": key,
                "label": label,
                "unit": unit,
                "n": len(pairs),
                "shipped_mean": float(np.mean(a)),
                "shipped_sd": float(np.std(a, ddof=1)) if len(a) > 1 else 0.0,
                "reference_mean": float(np.mean(b)),
                "reference_sd": float(np.std(b, ddof=1)) if len(b) > 1 else 0.0,
                "diff": diff,
                "diff_ci95": [lo, hi],
                "verdict": "speed" if key == "steps_per_s" else ("within noise" if noise else "differs"),
            }
        )
    return rows


def markdown(result: dict) -> str:
    """The comparison as a markdown table."""
    s, r = result["shipped_solver"], result["reference_solver"]
    a, b = result.get("shipped_label", "shipped"), result.get("variant_label", "reference")
    lines = [
        f"**{result['task']} × {result['robot']}**, {result['seeds']} seeds (scripted policy); {a} `{s}` vs {b} `{r}`",
        "",
        f"| metric | {a} (mean ± sd) | {b} (mean ± sd) | difference [95% CI] | verdict |",
        "|---|---|---|---|---|",
    ]
    for row in result["rows"]:
        unit = f" ({row['unit']})" if row["unit"] else ""
        lo, hi = row["diff_ci95"]
        seeds = f", {row['n']} seeds" if row["n"] != result["seeds"] else ""
        lines.append(
            f"| {row['label']}{unit}{seeds} | {row['shipped_mean']:.3g} ± {row['shipped_sd']:.2g} | "
            f"{row['reference_mean']:.3g} ± {row['reference_sd']:.2g} | {row['diff']:+.3g} [{lo:+.3g}, {hi:+.3g}] | {row['verdict']} |"
        )
    return "\n".join(lines) + "\n"


def parse_solver(items: list[str]) -> dict:
    """``key=value`` overrides of ``sim.solver`` (numbers)."""
    out = {}
    for item in items:
        key, _, value = item.partition("=")
        out[key] = float(value) if "." in value or "e" in value else int(value)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("spec", help="shipped task spec")
    ap.add_argument("--robot", default="jaco")
    ap.add_argument("--seeds", type=int, default=20, help="episodes per setting (seeds 0..N-1)")
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument(
        "--solver",
        nargs="+",
        default=[],
        metavar="KEY=VALUE",
        help="compare against the reference's settings with these sim.solver keys changed "
        "(e.g. contact_breaking_threshold_m=0.002: which of the differences matters)",
    )
    ap.add_argument(
        "--without-rest",
        action="store_true",
        help="compare against the shipped spec with particle sets' rest switched off (always simulated), "
        "at the shipped solver settings",
    )
    ap.add_argument(
        "--against-artifact",
        metavar="DIR",
        help="compare against this artifact of the same task and robot (e.g. compiled before a compiler change), "
        "at its own settings",
    )
    ap.add_argument("--artifacts", help="where to compile (default: a temporary directory)")
    ap.add_argument("--json", help="write the full result (per-episode figures too) here")
    ap.add_argument("--markdown", help="write the table here")
    ap.add_argument(
        "--from-json",
        nargs="+",
        metavar="RESULT",
        help="re-tabulate a result written by --json (no episodes run); with two results of the same "
        "seeds, compare their compared settings (the first's as 'shipped', the second's as 'reference')",
    )
    args = ap.parse_args(argv)

    if args.from_json:
        result = json.loads(Path(args.from_json[0]).read_text())
        if len(args.from_json) == 2:
            other = json.loads(Path(args.from_json[1]).read_text())
            if [e["seed"] for e in other["episodes"]["reference"]] != [
                e["seed"] for e in result["episodes"]["reference"]
            ]:
                raise SystemExit("--from-json: the two results ran different seeds")
            result["shipped_solver"], result["reference_solver"] = result["reference_solver"], other["reference_solver"]
            result["shipped_label"] = result.get("variant_label", "reference")
            result["variant_label"] = other.get("variant_label", "reference")
            result["episodes"] = {
                "shipped": result["episodes"]["reference"],
                "reference": other["episodes"]["reference"],
            }
        result["rows"] = compare(result["episodes"]["shipped"], result["episodes"]["reference"])
    else:
        result = run(args)
        if result is None:
            return 2
    table = markdown(result)
    print(table)
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(result, indent=1))
    if args.markdown:
        Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
        Path(args.markdown).write_text(table)
    return 0


def write_rest_off_variant(spec_path: str | Path, spec, out: Path) -> Path | None:
    """Write the spec file ``out``: the spec at ``spec_path`` with every particle set's ``rest``
    switched off; None when no set has one."""
    names = [name for name, ps in spec.particles.items() if ps.rest is not None]
    if not names:
        return None
    out.parent.mkdir(parents=True, exist_ok=True)
    sets = "".join(f"  {name}:\n    rest: null\n" for name in names)
    out.write_text(
        f"# {Path(spec_path).name} with its particles always simulated (benchmarks/physics_settings.py)\n"
        f"extends: {Path(spec_path).resolve()}\nparticles:\n{sets}"
    )
    return out


def run(args: argparse.Namespace) -> dict | None:
    """Compile both settings (or take ``--against-artifact``) and run the seeds on each; None when
    there is nothing to compare."""
    spec = load_spec(args.spec).spec
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.artifacts or tmp)
        t0 = time.perf_counter()
        if args.against_artifact:
            variant_dir = Path(args.against_artifact)
            theirs = Manifest.read(variant_dir, verify=True)
            if (theirs.task, theirs.robot_name) != (spec.name, args.robot):
                print(
                    f"{variant_dir}: compiled for {theirs.task} on {theirs.robot_name}, not {spec.name} on {args.robot}",
                    file=sys.stderr,
                )
                return None
            variant_solver = {
                "sub_steps": theirs.sim.sub_steps,
                "iterations": theirs.sim.solver_iterations,
                "contact_breaking_threshold_m": theirs.sim.contact_breaking_threshold,
            }
            label = f"the artifact at {variant_dir}"
        else:
            variant_spec = _variant_spec(args, spec, root)
            if variant_spec is None:
                return None
            variant, variant_solver, label, tag = variant_spec
            variant_dir = compile_task(variant, args.robot, root / f"{spec.name}-{args.robot}-{tag}").out_dir
        shipped_dir = compile_task(args.spec, args.robot, root / f"{spec.name}-{args.robot}-shipped").out_dir
        compile_s = time.perf_counter() - t0
        shipped = run_episodes(shipped_dir, seeds)
        other = run_episodes(variant_dir, seeds)
    return {
        "task": spec.name,
        "robot": args.robot,
        "seeds": len(seeds),
        "first_seed": args.first_seed,
        "shipped_solver": solver_settings(spec),
        "reference_solver": variant_solver,
        "variant_label": label,
        "command": " ".join(["benchmarks/physics_settings.py", *sys.argv[1:]]),
        "compile_s": round(compile_s, 1),
        "rows": compare(shipped, other),
        "episodes": {"shipped": shipped, "reference": other},
    }


def _variant_spec(args: argparse.Namespace, spec, root: Path) -> tuple[Path, dict, str, str] | None:
    """The compared spec file (written under ``root``), its solver settings, its label and its
    file tag; None (after saying why) when there is nothing to compare."""
    if args.without_rest:
        tag = "rest-off"
        variant = write_rest_off_variant(args.spec, spec, root / "specs" / f"{spec.name}-{tag}.yaml")
        if variant is None:
            print(f"{spec.name}: no particle set rests in a container; nothing to compare", file=sys.stderr)
            return None
        return variant, solver_settings(spec), "rest off (always simulated)", tag
    ref = reference_solver(spec.name)
    if ref is None:
        print(f"{spec.name}: the reference has no such task", file=sys.stderr)
        return None
    variant_solver = {**ref, **parse_solver(args.solver)}
    if variant_solver == solver_settings(spec):
        print(f"{spec.name}: the shipped solver settings are the compared ones; nothing to compare", file=sys.stderr)
        return None
    label = "reference" if not args.solver else "reference with " + ", ".join(args.solver)
    tag = "reference" if not args.solver else "variant-" + "-".join(args.solver).replace("=", "")
    variant = write_solver_variant(args.spec, variant_solver, root / "specs" / f"{spec.name}-{tag}.yaml")
    return variant, variant_solver, label, tag


if __name__ == "__main__":
    raise SystemExit(main())

"""The evidence behind a particle set's ``rest`` (docs/physics.md, Drinking's resting water).

``creep``: how far always-simulated particles move in their container when it turns. For each
angle θ the container's grip is turned from upright about its x axis over θ/5 env steps (at least
2), the arm holding still, then held 20 steps; printed per angle: the particles' mean and largest
movement in the container frame since they rested upright (mm), the top of the particles above
the container's floor (cm) and how many are left in it.

``speed``: the bench's random-action episodes (``steps`` steps, repeat r: ``reset(seed=r)`` and
``action_space.seed(r)``) on the spec as shipped and with its particles always simulated, repeats
interleaved: env steps/s by the wall clock and per CPU second (``time.process_time``, which the
other processes of a shared machine do not count against), medians, and the share of steps with
every particle carried. Run e.g.::

    .venv/bin/python benchmarks/particle_rest.py creep specs/tasks/drinking.yaml --robot jaco
    .venv/bin/python benchmarks/particle_rest.py speed specs/tasks/drinking.yaml --robot jaco
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pybullet as pb

sys.path.insert(0, str(Path(__file__).parent))
from physics_settings import write_rest_off_variant  # noqa: E402

from assistive_compiler.compile.compiler import compile_task  # noqa: E402
from assistive_compiler.runtime.env import AssistiveEnv  # noqa: E402
from assistive_compiler.spec.load import load_spec  # noqa: E402


def container_frame(env, ps, box) -> np.ndarray:
    """Every particle of set ``ps`` in the frame of container ``box``, (n, 3) m."""
    c = env.client
    pos, orn = env.base_pose(box.body)
    inv = pb.invertTransform(pos, orn)
    return np.array(
        [
            pb.multiplyTransforms(*inv, pb.getBasePositionAndOrientation(pid, physicsClientId=c)[0], (0, 0, 0, 1))[0]
            for pid in env.particle_ids(ps.name)
        ]
    )


def creep(artifact: Path, box, angles: list[int]) -> None:
    """``artifact`` simulates the particles always; ``box``: the container they rest in when shipped."""
    env = AssistiveEnv(artifact)
    ps = env.manifest.particles[0]
    grip = env.world.tool_constraints[box.body]
    hold = np.zeros(env.action_space.shape)
    print(
        "| turned by | mean / max movement (mm) | top above the floor (cm) | left in the container |\n|---|---|---|---|"
    )
    for theta in angles:
        env.reset(seed=0)
        for _ in range(10):
            env.step(hold)
        rested = container_frame(env, ps, box)
        n = max(2, theta // 5)
        for k in range(1, n + 1):
            turn = pb.getQuaternionFromEuler([-math.radians(theta * k / n), 0, 0])
            pb.changeConstraint(grip, jointChildFrameOrientation=turn, maxForce=500, physicsClientId=env.client)
            env.step(hold)
        for _ in range(20):
            env.step(hold)
        left = env.particles.active[ps.name]
        moved = np.linalg.norm(container_frame(env, ps, box) - rested, axis=1)[left]
        top = container_frame(env, ps, box)[left, 2].max()
        print(f"| {theta}° | {moved.mean() * 1e3:.1f} / {moved.max() * 1e3:.1f} | {top * 1e2:.1f} | {left.sum()} |")
    env.close()


def speed(artifacts: dict[str, Path], steps: int, repeats: int) -> None:
    envs = {label: AssistiveEnv(path) for label, path in artifacts.items()}
    wall = {label: [] for label in envs}
    cpu = {label: [] for label in envs}
    carried = {label: [] for label in envs}
    for r in range(repeats):
        for label, env in envs.items():
            env.action_space.seed(r)
            env.reset(seed=r)
            all_carried = 0
            t0, c0 = time.perf_counter(), time.process_time()
            for _ in range(steps):
                env.step(env.action_space.sample())
                sets = env.particles.carried  # (empty without rest)
                all_carried += bool(sets) and all(bool(c[env.particles.active[name]].all()) for name, c in sets.items())
            wall[label].append(steps / (time.perf_counter() - t0))
            cpu[label].append(steps / (time.process_time() - c0))
            carried[label].append(all_carried / steps)
    for label in envs:
        print(
            f"{label}: {statistics.median(wall[label]):.1f} env steps/s (wall), {statistics.median(cpu[label]):.1f} per CPU second; "
            f"per repeat wall {[round(x, 1) for x in wall[label]]}, CPU {[round(x, 1) for x in cpu[label]]}, "
            f"steps with every particle carried {[round(x, 2) for x in carried[label]]}"
        )
        envs[label].close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("what", choices=["creep", "speed"])
    ap.add_argument("spec")
    ap.add_argument("--robot", default="jaco")
    ap.add_argument("--angles", default="0,5,10,15,20,30,40,50,60,70,80", help="creep: turns, degrees")
    ap.add_argument("--steps", type=int, default=400, help="speed: steps per repeat")
    ap.add_argument("--repeats", type=int, default=5, help="speed: repeats")
    args = ap.parse_args(argv)
    spec = load_spec(args.spec).spec
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        off = write_rest_off_variant(args.spec, spec, root / "rest-off.yaml")
        if off is None:
            print(f"{spec.name}: no particle set rests in a container", file=sys.stderr)
            return 2
        always = compile_task(off, args.robot, root / "rest-off").out_dir
        shipped = compile_task(args.spec, args.robot, root / "shipped")
        if args.what == "creep":
            creep(
                always,
                next(ps.rest.container for ps in shipped.manifest.particles if ps.rest),
                [int(a) for a in args.angles.split(",")],
            )
        else:
            speed({"carried at rest (shipped)": shipped.out_dir, "always simulated": always}, args.steps, args.repeats)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

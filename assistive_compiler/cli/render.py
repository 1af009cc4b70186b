"""The picture commands: ``render`` (one episode as a GIF or a PNG strip, headless) and
``render-person`` (the person variants a spec declares, side by side).

:func:`record`, :func:`write_picture` and :func:`render_people` are plain functions other
commands reuse (``demo`` records its first episode with them).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from .common import EXIT_OK, add_library_argument, add_spec_arguments, make_env


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
    """``out``: a GIF of every frame at ``fps``, or a PNG strip (:func:`montage`)."""
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
    from ..policies import make_policy

    env = make_env(args.spec, args.robot, args.out_dir, render_mode="rgb_array", render_size=(args.width, args.height))
    policy = make_policy(args.policy, env, seed=args.seed)
    frames, summary = record(env, policy, args.seed, args.every)
    env.close()
    write_picture(frames, Path(args.out), fps=max(1, 10 // args.every))
    print(f"wrote {args.out} ({len(frames)} frames; return {summary['return']:.1f}, success {'yes' if summary['success'] else 'no'})")
    return EXIT_OK


def render_people(artifact_dir: Path, width: int = 360, height: int = 480) -> np.ndarray:
    """One frontal picture per person variant of an artifact (in the task's posture, on its seat),
    side by side and labelled with name, sex, mass and standing height."""
    import pybullet as pb
    from PIL import Image, ImageDraw

    from ..runtime.world import PARK, World

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

    from ..compile.compiler import compile_task

    result = compile_task(args.spec, args.robot, args.out_dir)
    picture = render_people(result.out_dir)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(picture).save(args.out)
    names = ", ".join(v.name for v in result.manifest.person.variants)
    print(f"wrote {args.out} ({names})")
    return EXIT_OK


def add_commands(sub) -> None:
    p = sub.add_parser("render", help="write a GIF (or a PNG strip) of one episode, headless")
    add_spec_arguments(p)
    p.add_argument("--out", required=True, help="output .gif or .png")
    p.add_argument("--every", type=int, default=4, help="record every N steps (default 4)")
    p.add_argument("--width", type=int, default=480)
    p.add_argument("--height", type=int, default=360)
    p.add_argument("--out-dir", dest="out_dir", help="artifact directory")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("render-person", help="draw the person variants a spec declares, side by side (PNG)")
    add_library_argument(p)
    p.add_argument("spec", help="task spec file")
    p.add_argument("--robot", help="robot to compile the task for (default: the spec's default)")
    p.add_argument("--out", required=True, help="output .png")
    p.add_argument("--out-dir", dest="out_dir", help="artifact directory")
    p.set_defaults(func=cmd_render_person)

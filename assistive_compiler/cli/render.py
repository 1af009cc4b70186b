"""The picture commands: ``render`` (one episode as a GIF or a PNG strip, headless) and
``render-person`` (the person variants a spec declares, side by side).

Episode frames and the files they go into: :mod:`assistive_compiler.pictures`;
:func:`render_people` is a plain function other code reuses.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..errors import SpecError
from ..pictures import check_picture_path, episode_frames, write_picture
from ..rotation import quat_matrix
from .common import EXIT_BAD_INPUT, EXIT_OK, SPEC_HELP, add_library_argument, add_spec_arguments, make_env
from .run import TRACE_HELP, add_coop_arguments, human_policy_for, trace_fits

COOP_PICTURE_HELP = (
    "co-optimisation: the person acts too, by --human-policy (a co-optimised pair plays both agents anyway)"
)


def control_hz(manifest) -> float:
    """Env steps per simulated second (the paper's 10 Hz control)."""
    return 1.0 / (manifest.sim.time_step * manifest.sim.frame_skip)


def parse_camera(text: str | None) -> dict | None:
    """``--camera``: ``eye=X,Y,Z target=X,Y,Z fov=DEG`` (any of them, space- or semicolon-separated)."""
    if not text:
        return None
    view, names = {}, {"eye": "eye", "target": "target", "fov": "fov_deg", "fov_deg": "fov_deg"}
    for item in text.replace(";", " ").split():
        key, _, value = item.partition("=")
        try:
            numbers = [float(v) for v in value.split(",")]
        except ValueError:
            numbers = []
        want = 1 if names.get(key) == "fov_deg" else 3
        if key not in names or len(numbers) != want:
            raise SpecError.at(
                "--camera",
                f"'{item}': expected eye=X,Y,Z, target=X,Y,Z or fov=DEG (metres in the world frame, degrees), "
                "e.g. --camera 'eye=-0.9,-1.4,1.5 target=-0.1,-0.15,0.85 fov=50'",
            )
        view[names[key]] = numbers[0] if want == 1 else tuple(numbers)
    return view


def cmd_render(args: argparse.Namespace) -> int:
    if not trace_fits("render", args):
        return EXIT_BAD_INPUT

    out = Path(args.out)
    check_picture_path(out)
    view = parse_camera(args.camera)
    env = make_env(
        args.spec, args.robot, args.out_dir, render_mode="rgb_array", render_size=(args.width, args.height), camera=view
    )
    env.show_frames = args.frames
    if args.trace:  # the scripted policy noting its waypoint events (reading only: the same episode)
        from ..policies import make_policy

        target, act = env, make_policy("scripted", env, seed=args.seed, trace=True)
    else:
        target, act = _player(args, env)
    frames, summary = episode_frames(target, act, args.seed, args.every)
    fps = args.fps or control_hz(env.manifest) / args.every
    trace = act.trace_report(args.seed) if args.trace else []  # where the episode ended: read before closing
    env.close()
    write_picture(frames, out, fps=fps)
    print(
        f"wrote {args.out} ({len(frames)} frames at {fps:g} fps; return {summary['return']:.1f}, success {'yes' if summary['success'] else 'no'})"
    )
    if trace:
        print("\n".join(trace))
    return EXIT_OK


def _player(args: argparse.Namespace, env):
    """``(target, act)`` that plays ``--policy``: under ``--coop`` the person acts too, by
    ``--human-policy`` (default: a co-optimised pair's own person, else random); a co-optimised
    pair plays both agents either way."""
    from ..policies import make_player

    if not args.coop:
        return make_player(args.policy, env, seed=args.seed)
    from ..coop.policies import pair_policy
    from ..policies.pair import both_agents

    args.human_policy = human_policy_for(args.policy, args.human_policy)
    return both_agents(env, pair_policy(env, args.policy, args.human_policy, args.seed))


def render_people(artifact_dir: Path, width: int = 360, height: int = 480) -> np.ndarray:
    """One frontal picture per person variant of an artifact (in the task's posture, on its seat),
    side by side and labelled with name, sex, mass and standing height."""
    import pybullet as pb
    from PIL import Image, ImageDraw

    from ..runtime.bodies import PARK
    from ..runtime.world import World

    world = World(artifact_dir)
    m, c = world.m, world.client
    world.set_base_frame(world.robot, (PARK[0], PARK[1] - 20, PARK[2]), (0, 0, 0, 1))  # the robot is not the subject
    for att in m.tools:
        if att.welded:  # parked with the robot
            continue
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
        body = m.body(variant.body)
        # The camera sits in front of the person in the person's own base frame (the person faces
        # its base's -Y, head toward +Z), so a supine person on a bed is seen from above, head up,
        # and a seated one from the front, wherever the furniture stands.
        rotation = quat_matrix(body.orientation)
        target = np.asarray(body.position) + rotation @ [0.0, 0.0, -0.3]
        eye = target + rotation @ [0.0, -2.6, 0.35]
        view = pb.computeViewMatrix(eye.tolist(), target.tolist(), (rotation @ [0, 0, 1]).tolist(), physicsClientId=c)
        proj = pb.computeProjectionMatrixFOV(40, width / height, 0.05, 10, physicsClientId=c)
        rgba = pb.getCameraImage(
            width, height, view, proj, renderer=pb.ER_TINY_RENDERER, lightDirection=[1, -2, 2], physicsClientId=c
        )[2]
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
    p.add_argument("--out", required=True, help="output .gif or .mp4 (every recorded frame) or .png (a strip of four)")
    p.add_argument("--every", type=int, default=4, help="record every N steps (default 4)")
    p.add_argument(
        "--fps",
        type=float,
        help="frames per second of a GIF or MP4 (default: simulated speed, "
        "the control rate / --every: 2.5 at 10 Hz and --every 4)",
    )
    p.add_argument(
        "--camera", help="camera instead of the task's: 'eye=X,Y,Z target=X,Y,Z fov=DEG' (world frame, m; any subset)"
    )
    p.add_argument("--width", type=int, default=480)
    p.add_argument("--height", type=int, default=360)
    p.add_argument("--out-dir", dest="out_dir", help="artifact directory")
    p.add_argument(
        "--frames",
        action="store_true",
        help="draw the end effector's, tools' and targets' frames (x red, y green, z blue, 6 cm) with their names",
    )
    add_coop_arguments(p, COOP_PICTURE_HELP)
    p.add_argument("--trace", action="store_true", help=TRACE_HELP + ", after the picture")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("render-person", help="draw the person variants a spec declares, side by side (PNG)")
    add_library_argument(p)
    p.add_argument("spec", help=SPEC_HELP)
    p.add_argument("--robot", help="robot to compile the task for (default: the spec's default)")
    p.add_argument("--out", required=True, help="output .png")
    p.add_argument("--out-dir", dest="out_dir", help="artifact directory")
    p.set_defaults(func=cmd_render_person)

"""A contact sheet of every shipped task × robot from its task camera: the first frame after a
seeded reset, labelled, one row per task. Look at it after changing a ``camera:`` section.

    python benchmarks/camera_sheet.py OUT.png [--size 320x240] [--artifacts DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.gym_ids import shipped_tasks
from assistive_compiler.runtime.env import AssistiveEnv


def sheet(width: int, height: int, artifacts: Path) -> np.ndarray:
    rows = []
    for task in shipped_tasks():
        panels = []
        for robot in task.robots:
            out = compile_task(task.spec, robot, artifacts / f"{task.name}-{robot}").out_dir
            env = AssistiveEnv(out, render_mode="rgb_array", render_size=(width, height))
            env.reset(seed=0)
            image = Image.fromarray(env.render())
            env.close()
            ImageDraw.Draw(image).text((6, 6), f"{task.name} / {robot}", fill=(0, 0, 0))
            panels.append(np.asarray(image))
            print(f"{task.name} {robot}", flush=True)
        panels += [np.full_like(panels[0], 255)] * (5 - len(panels))
        rows.append(np.concatenate(panels, axis=1))
    return np.concatenate(rows, axis=0)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out")
    p.add_argument("--size", default="320x240")
    p.add_argument("--artifacts", default="generated")
    args = p.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    Image.fromarray(sheet(width, height, Path(args.artifacts))).save(args.out)


if __name__ == "__main__":
    main()

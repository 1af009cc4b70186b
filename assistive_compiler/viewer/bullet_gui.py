"""``view --gui``: replay a recording in pybullet's own GUI window, where a display exists.

The window gets visual-only copies of every link's visuals (the same meshes the browser view
draws, :mod:`.meshes`) and the food/water particles, posed from the recording state by state and
looping until the window is closed or Ctrl-C. Nothing is simulated.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

from ..record.format import Recording
from .meshes import link_visuals

NO_DISPLAY = (
    "view --gui: no display ($DISPLAY is not set), so pybullet's GUI cannot open here. "
    "Leave out --gui to view the task in a browser (it works on a headless server: open the printed URL, "
    "or forward the port with ssh -L)."
)


def replay_in_gui(artifact_dir: Path, recording: Recording, speed: float = 1.0) -> int:
    """Loop the recording in a pybullet GUI window; returns 0 when closed, 1 without a display."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        print(NO_DISPLAY, file=sys.stderr)
        return 1
    import pybullet as pb

    c = pb.connect(pb.GUI)
    if c < 0:
        print(f"view --gui: pybullet could not open its GUI on display {os.environ.get('DISPLAY')!r}", file=sys.stderr)
        return 1
    h, a = recording.header, recording.arrays
    pb.configureDebugVisualizer(pb.COV_ENABLE_GUI, 0, physicsClientId=c)
    placed: list[tuple[int, int]] = []  # (pybullet body, link column)
    for body in h["bodies"]:
        if body["kind"] == "garment" or (body["kind"] == "person" and body["name"] != h["person_body"]):
            continue
        visuals = link_visuals(artifact_dir / body["urdf"])
        for link in body["links"]:
            column = h["links"].index([body["name"], link])
            for v in visuals.get(link, []):
                shape = pb.createVisualShape(
                    pb.GEOM_MESH,
                    vertices=v.vertices.tolist(),
                    indices=v.faces.reshape(-1).tolist(),
                    rgbaColor=list(v.rgba),
                    physicsClientId=c,
                )
                placed.append((pb.createMultiBody(0, -1, shape, physicsClientId=c), column))
    particles = []
    for p in h["particles"]:
        shapes = [
            pb.createVisualShape(pb.GEOM_SPHERE, radius=p["radius"], rgbaColor=list(rgba), physicsClientId=c)
            for rgba in p["colors"]
        ]
        particles.append((p["name"], [pb.createMultiBody(0, -1, s, physicsClientId=c) for s in shapes]))
    pb.resetDebugVisualizerCamera(1.6, -35, -25, [-0.12, -0.15, 0.85], physicsClientId=c)
    try:
        while pb.isConnected(c):
            for k in range(recording.steps + 1):
                for bid, column in placed:
                    pb.resetBasePositionAndOrientation(
                        bid, a["link_pos"][k, column], a["link_quat"][k, column], physicsClientId=c
                    )
                for name, ids in particles:
                    where, active = a[f"particles/{name}"][k], a[f"particles_active/{name}"][k]
                    for bid, p, on in zip(ids, where, active):
                        pb.resetBasePositionAndOrientation(
                            bid, p if on else np.array([0.0, 500.0, 50.0]), (0, 0, 0, 1), physicsClientId=c
                        )
                time.sleep(h["dt"] / speed)
    except (KeyboardInterrupt, pb.error):  # Ctrl-C, or the window was closed mid-frame
        pass
    finally:
        if pb.isConnected(c):
            pb.disconnect(c)
    return 0

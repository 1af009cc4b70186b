"""The 3D scene of a viser server, posed from a recording (see :mod:`assistive_compiler.record.format`).

Every link is a viser frame node ``/bodies/<body>/<link>`` placed at the link's recorded world
pose; its visuals are child meshes in the link frame (:mod:`.meshes`). Targets are small spheres,
particles and markers point clouds (consumed, lost or cleared ones hidden), garments meshes whose
vertices are the recorded nodes. Person variants other than the episode's are hidden.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..record.format import Recording
from ..rotation import wxyz
from .meshes import garment_faces, link_visuals

TARGET_RGBA = (0.1, 0.8, 0.1, 1.0)


def _rgb255(rgba) -> tuple[int, int, int]:
    return tuple(int(round(255 * float(c))) for c in rgba[:3])


class RecordingScene:
    """Scene nodes for one artifact, shown at any state of a recording of it."""

    def __init__(self, server, artifact_dir: str | Path, recording: Recording):
        self.server = server
        self.dir = Path(artifact_dir)
        header = recording.header
        scene = server.scene
        scene.add_grid("/floor", width=4.0, height=4.0, cell_size=0.25, position=(0.0, 0.0, 0.0))
        self.frames = []  # (column, frame handle) per link
        self.body_nodes: dict[str, object] = {}
        for body in header["bodies"]:
            if body["kind"] == "garment":
                continue
            visuals = link_visuals(self.dir / body["urdf"])
            self.body_nodes[body["name"]] = scene.add_frame(f"/bodies/{body['name']}", show_axes=False)
            for link in body["links"]:
                frame = scene.add_frame(f"/bodies/{body['name']}/{link}", show_axes=False)
                self.frames.append((header["links"].index([body["name"], link]), frame))
                for k, v in enumerate(visuals.get(link, [])):
                    scene.add_mesh_simple(
                        f"/bodies/{body['name']}/{link}/visual_{k}",
                        v.vertices,
                        v.faces,
                        color=_rgb255(v.rgba),
                        opacity=None if v.rgba[3] >= 1 else v.rgba[3],
                    )
        self.person_bodies = [b["name"] for b in header["bodies"] if b["kind"] == "person"]
        self.targets = [
            scene.add_icosphere(f"/targets/{name}", radius=0.015, color=_rgb255(TARGET_RGBA))
            for name in header["targets"]
        ]
        self.particles = {
            p["name"]: (np.asarray(p["colors"])[:, :3] * 255).astype(np.uint8) for p in header["particles"]
        }
        self.particle_size = {p["name"]: 2.0 * p["radius"] for p in header["particles"]}
        self.marker_rgb = {m["name"]: _rgb255(m["rgba"] or (0.2, 0.4, 1.0, 1.0)) for m in header["markers"]}
        self.garments = {}
        for body in header["bodies"]:
            if body["kind"] == "garment":
                faces = garment_faces(self.dir / body["urdf"])
                nodes = recording.arrays[f"garment/{body['name']}"][0]
                self.garments[body["name"]] = scene.add_mesh_simple(
                    f"/garments/{body['name']}", nodes.astype(np.float32), faces, color=(120, 160, 220), side="double"
                )
        self.recording = recording

    def show(self, k: int) -> None:
        """Pose everything as at state ``k`` of the recording (0: after reset)."""
        rec = self.recording
        a, h = rec.arrays, rec.header
        k = int(np.clip(k, 0, rec.steps))
        scene = self.server.scene
        with self.server.atomic():
            for name, node in self.body_nodes.items():
                node.visible = name not in self.person_bodies or name == h["person_body"]
            pos, quat = a["link_pos"][k], a["link_quat"][k]
            for column, frame in self.frames:
                frame.position = pos[column]
                frame.wxyz = wxyz(quat[column])
            for node, p in zip(self.targets, a["target_pos"][k]):
                node.position = p
            for name, colors in self.particles.items():
                shown = a[f"particles_active/{name}"][k]
                scene.add_point_cloud(
                    f"/particles/{name}",
                    a[f"particles/{name}"][k][shown].astype(np.float32),
                    colors[shown],
                    point_size=self.particle_size[name],
                    point_shape="circle",
                )
            for name, rgb in self.marker_rgb.items():
                left = a[f"markers_remaining/{name}"][k]
                scene.add_point_cloud(
                    f"/markers/{name}",
                    a[f"markers/{name}"][k][left].astype(np.float32),
                    rgb,
                    point_size=0.016,
                    point_shape="circle",
                )
            for name, mesh in self.garments.items():
                mesh.vertices = a[f"garment/{name}"][k].astype(np.float32)

    def remove(self) -> None:
        """Take every node off the server (before showing another episode)."""
        self.server.scene.reset()

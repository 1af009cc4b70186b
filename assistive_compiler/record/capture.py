"""Reading what an env's world looks like now, for a recording: link poses, targets, particles,
markers and garment nodes (see :mod:`.format` for shapes, units and frames).

Only reads: no body is moved, no snapshot slot is added, nothing the physics or the terms use is
changed, so a recorded episode is the unrecorded one (tested: same returns for the same seed).
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..references import PointHandle
from ..rotation import quat_rotate


class SceneReader:
    """Reads one :class:`~assistive_compiler.runtime.env.AssistiveEnv`'s scene state."""

    def __init__(self, env):
        self.env = env
        m = env.manifest
        self.bodies: list[dict] = []
        self.links: list[list[str]] = []
        #: Per body: (name, pybullet id, [link indices ≥ 0], their columns, column of the base)
        self._reads: list[tuple] = []
        for body in m.bodies:
            links = env.links(body.name)
            names = sorted(links, key=links.get)  # base (-1) first, then joint order
            first = len(self.links)
            self.links += [[body.name, name] for name in names]
            self.bodies.append({"name": body.name, "kind": body.kind, "urdf": body.urdf, "links": names})
            children = [links[n] for n in names if links[n] >= 0]
            self._reads.append(
                (
                    body.name,
                    env.body_id(body.name),
                    children,
                    [first + k for k, n in enumerate(names) if links[n] >= 0],
                    first,
                )
            )
        for g in m.garments:
            self.bodies.append({"name": g.name, "kind": "garment", "urdf": g.obj, "links": []})
        self.targets = list(m.targets)

    def header(self) -> dict:
        """The scene part of a recording's header (bodies, link columns, targets, particle and marker sets)."""
        m = self.env.manifest
        return {
            "bodies": self.bodies,
            "links": self.links,
            "targets": self.targets,
            "particles": [
                {"name": p.name, "count": p.count, "radius": p.radius, "colors": [list(c) for c in p.colors]}
                for p in m.particles
            ],
            "markers": [
                {
                    "name": s.name,
                    "count": len(self.env.marker_state(s.name)[1]),
                    "radius": s.radius,
                    "rgba": list(s.show_rgba) if s.show_rgba else None,
                }
                for s in m.markers
            ],
            "garments": [{"name": g.name, "nodes": len(g.nodes_in_held)} for g in m.garments],
        }

    def link_poses(self) -> tuple[np.ndarray, np.ndarray]:
        """(L, 3) positions and (L, 4) quaternions of every link's URDF frame, world."""
        env, c = self.env, self.env.client
        pos = np.empty((len(self.links), 3))
        quat = np.empty((len(self.links), 4))
        for name, body_id, children, columns, base in self._reads:
            pos[base], quat[base] = env.base_pose(name)
            if children:
                for col, s in zip(
                    columns, pb.getLinkStates(body_id, children, computeForwardKinematics=1, physicsClientId=c)
                ):
                    pos[col], quat[col] = s[4], s[5]
        return pos, quat

    def target_positions(self, pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
        """(n_targets, 3) world positions: a target the terms use is read as they read it; any other
        from its link's pose (``pos``/``quat`` from :meth:`link_poses`) and its offset."""
        env = self.env
        snap, m = env.snap, env.manifest
        out = np.empty((len(self.targets), 3))
        for k, name in enumerate(self.targets):
            if name in snap.target_slots:
                out[k] = snap.position(PointHandle(snap.target_slots[name], name))
                continue
            t = m.targets[name]
            body = env.person_body if t.body == "person" else t.body
            j = self.links.index([body, t.link])
            out[k] = pos[j] + quat_rotate(quat[j], np.asarray(t.offset, dtype=float))
        return out

    def state(self) -> dict[str, np.ndarray]:
        """Every per-state array of one recording row (names as in :mod:`.format`)."""
        env = self.env
        pos, quat = self.link_poses()
        row = {"link_pos": pos, "link_quat": quat, "target_pos": self.target_positions(pos, quat)}
        for ps in env.manifest.particles:
            row[f"particles/{ps.name}"], row[f"particles_active/{ps.name}"] = env.particle_state(ps.name)
        for ms in env.manifest.markers:
            row[f"markers/{ms.name}"], row[f"markers_remaining/{ms.name}"] = env.marker_state(ms.name)
        for name, nodes in env.garment_nodes().items():
            row[f"garment/{name}"] = nodes
        return row

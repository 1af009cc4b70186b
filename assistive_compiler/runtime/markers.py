"""Markers on the person (spots to wipe in bed bathing): each is cleared once per episode when a
contact between the clearing tool link and the person lies within the set's radius of it.

Marker positions are stored per person variant in their limb's link frame (the compiler laid them
out); each step they are moved with their limb (one batched read through the snapshot) only when
the tool touches the person, so a step without contact costs one contact query.
"""

from __future__ import annotations

import numpy as np
import pybullet as pb

from ..rotation import quat_matrix
from .component import Episode, EpisodeComponent
from .snapshot import Snapshot
from .world import World

MARKER_RADIUS_M = 0.008
"""Radius of a marker's dot in renders, m."""


class MarkerSystem(EpisodeComponent):
    """All marker sets of a world, for the active person variant."""

    def __init__(self, world: World, snap: Snapshot):
        self.world, self.snap = world, snap
        self.sets = world.m.markers
        self._tool = {
            ms.name: (world.bodies[ms.tool].id, world.bodies[ms.tool].links[ms.tool_link]) for ms in self.sets
        }
        self.remaining: dict[str, np.ndarray] = {}
        self._groups: dict[str, list[tuple[int, np.ndarray, np.ndarray]]] = {}

    def reset(self, episode: Episode) -> None:
        """All markers of the episode's person variant back, none cleared."""
        assert episode.variant is not None, "markers reset after the person_variant event"
        for ms in self.sets:
            points = episode.variant.markers[ms.name]
            groups = []
            for link in dict.fromkeys(p.link for p in points):
                index = np.array([k for k, p in enumerate(points) if p.link == link])
                offsets = np.array([points[k].offset for k in index], dtype=float)
                groups.append((self.snap.link_slot("person", link), index, offsets))
            self._groups[ms.name] = groups
            self.remaining[ms.name] = np.ones(len(points), dtype=bool)
            self.snap.events[ms.name] = 0

    def positions(self, name: str) -> np.ndarray:
        """World positions of every marker of the set (cleared ones too), (N, 3) m."""
        snap = self.snap
        out = np.empty((len(self.remaining[name]), 3))
        for slot, index, offsets in self._groups[name]:
            out[index] = snap.pos[slot] + offsets @ quat_matrix(snap.orn[slot]).T
        return out

    def after_step(self) -> None:
        """Clear the markers near this step's contacts (after physics and the snapshot refresh)."""
        c = self.world.client
        person = self.snap.handle("person").id
        for ms in self.sets:
            tool_id, tool_link = self._tool[ms.name]
            contacts = pb.getContactPoints(bodyA=tool_id, bodyB=person, linkIndexA=tool_link, physicsClientId=c)
            cleared = 0
            remaining = self.remaining[ms.name]
            if contacts and remaining.any():
                where = self.positions(ms.name)
                points = np.array([cp[6] for cp in contacts])  # on the person
                d = np.linalg.norm(where[:, None, :] - points[None, :, :], axis=2).min(axis=1)
                hit = remaining & (d <= ms.radius)
                cleared = int(hit.sum())
                remaining &= ~hit
            self.snap.events[ms.name] = cleared

    def count(self, name: str) -> int:
        return len(self.remaining[name])

    def visual_spheres(self) -> list[tuple[list[float], float, tuple]]:
        """(position, radius m, rgba) of each shown marker not yet cleared, for renders."""
        out = []
        for ms in self.sets:
            if ms.show_rgba is None:
                continue
            where = self.positions(ms.name)
            out += [
                (where[k].tolist(), MARKER_RADIUS_M, tuple(ms.show_rgba))
                for k in range(len(where))
                if self.remaining[ms.name][k]
            ]
        return out

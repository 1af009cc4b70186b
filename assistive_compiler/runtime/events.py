"""A reset as ordered events (the manifest's ``events``, :func:`assistive_compiler.artifact.reset_events`).

``AssistiveEnv.reset`` restores the saved world, then applies each event in the manifest's order to
one :class:`~.component.Episode`, whose ``rng`` (the env's ``np_random``) every draw comes from —
so the order of the events is the order of the draws, and a seed gives one episode:

* ``person_variant``: which person body (uniform; ``options["person_variant"]`` chooses it),
* ``reset`` of a component (:class:`~.component.EpisodeComponent`): the person (joint angles,
  then impairment), markers, reward terms with memory, particles, garments,
* ``surface_targets``: each surface-drawn target's point on the person (paper §III-B's itch),
* ``robot_start``: one of the variant's precomputed starts, with what the robot carries,
* ``furniture_noise``: a uniform offset of one piece of furniture (m, world frame),
* ``floor_friction``: the floor's lateral friction coefficient.

Each event is a function of the env (an :class:`EventTarget`), the episode and its own parameters (the manifest's event
model); :func:`bind_events` binds them once, when the env is built.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial
from typing import Protocol

import numpy as np
import pybullet as pb

from ..artifact import (
    Capsule,
    ComponentResetEvent,
    Event,
    FloorFrictionEvent,
    FurnitureNoiseEvent,
    Manifest,
    PersonVariantEvent,
    RobotStartEvent,
    SurfacePoint,
    SurfaceTargetsEvent,
)
from ..rotation import capsule_axes
from .binding import BoundTerm
from .bodies import PARK
from .component import Episode, EpisodeComponent
from .snapshot import Snapshot
from .world import World


class EventTarget(Protocol):
    """What the events read and drive of an env (:class:`~.env.AssistiveEnv` is one): its
    manifest, world and per-step snapshot, its components by name, and the robot's start command."""

    manifest: Manifest
    world: World
    snap: Snapshot
    components: dict[str, EpisodeComponent]

    def command_start(self, joints: list[float]) -> None:
        """The arm at ``joints`` (rad, action order), at rest, with position targets there."""


#: An event bound to an env: applied to each reset's episode.
BoundEvent = Callable[[Episode], None]


def draw_surface_point(
    capsules: Sequence[Capsule], rng: np.random.Generator
) -> tuple[str, np.ndarray, np.ndarray, np.ndarray]:
    """A point on one of the limbs' capsules, as the reference draws an itch (paper §III-B): a limb
    uniformly, the distance from its joint end U(r, L) along the axis, the azimuth U(0, 2π).
    Returns (link, point, outward normal, axis away from the joint), in the link frame (m)."""
    cap = capsules[int(rng.integers(len(capsules)))]
    start = np.asarray(cap.start)
    length, axis, u, v = capsule_axes(cap.start, cap.end)
    along = rng.uniform(min(cap.radius, length), length)
    azimuth = rng.uniform(0.0, 2 * np.pi)
    normal = np.cos(azimuth) * u + np.sin(azimuth) * v
    return cap.link, start + axis * along + cap.radius * normal, normal, axis


def draw_listed_point(points: Sequence[SurfacePoint], rng: np.random.Generator) -> SurfacePoint:
    """One of a surface target's listed points (``PersonVariant.surface_points``): a link uniformly,
    then one of its points uniformly (so a small link is drawn as often as a large one, as on capsules)."""
    links = list(dict.fromkeys(p.link for p in points))
    link = links[int(rng.integers(len(links)))]
    on_link = [p for p in points if p.link == link]
    return on_link[int(rng.integers(len(on_link)))]


# -- the events ---------------------------------------------------------------------------------
def person_variant(env: EventTarget, episode: Episode, event: PersonVariantEvent) -> None:
    """The episode's person body in place, the others parked asleep, person-attached targets at its offsets."""
    m, w, snap = env.manifest, env.world, env.snap
    variants = m.person.variants
    variant = variants[int(episode.rng.integers(len(variants)))]
    chosen = episode.options.get("person_variant")
    if chosen is not None:
        names = [v.name for v in variants]
        if chosen not in names:
            raise ValueError(f"unknown person variant {chosen!r}; this task has {', '.join(names)}")
        variant = variants[names.index(chosen)]
    episode.variant = w.active_variant = variant
    snap.begin_episode()
    for i, v in enumerate(variants):
        body = m.body(v.body)
        parked = (PARK[0] + 10.0 * i, PARK[1], PARK[2])
        w.set_base_frame(w.variant_bodies[v.name], body.position if v is variant else parked, body.orientation)
        w.set_asleep(w.variant_bodies[v.name], v is not variant)
    for name, offset in variant.target_offsets.items():
        if name in snap.target_offsets:
            snap.target_offsets[name] = np.asarray(offset, dtype=float)


def surface_targets(env: EventTarget, episode: Episode, event: SurfaceTargetsEvent) -> None:
    """Each surface-drawn target at a new point of the person: on its limbs' capsules, then on listed points."""
    variant, snap = episode.variant, env.snap
    assert variant is not None, "surface targets are drawn after the person_variant event"
    for name, capsules in variant.surfaces.items():
        link, point, normal, axis = draw_surface_point(capsules, episode.rng)
        snap.place_target(name, link, point, normal, axis)
    for name, points in variant.surface_points.items():
        p = draw_listed_point(points, episode.rng)
        snap.place_target(name, p.link, np.asarray(p.offset), np.asarray(p.normal), np.asarray(p.axis))


def robot_start(env: EventTarget, episode: Episode, event: RobotStartEvent) -> None:
    """The robot at one of the variant's starts — base pose, arm (and followers, wheels) at rest
    with their motor targets there — the tools in the hand, carried furniture under the base."""
    m, w, c = env.manifest, env.world, env.world.client
    assert episode.variant is not None, "the robot's start is drawn after the person_variant event"
    k = int(episode.rng.integers(len(episode.variant.starts)))
    start = episode.variant.starts[k]
    episode.start_index = k
    w.set_base_frame(w.robot, start.base_position, start.base_orientation)
    env.command_start(list(start.joints))
    for att in m.tools:  # tools follow the hand exactly (a welded one is a part of it)
        if att.welded:
            continue
        link_pos, link_orn = w.link_frame(w.robot, w.robot.links[att.parent_link])
        pos, orn = pb.multiplyTransforms(link_pos, link_orn, att.position, att.orientation)
        w.set_base_frame(w.bodies[att.body], pos, orn)
        pb.resetBaseVelocity(w.bodies[att.body].id, (0, 0, 0), (0, 0, 0), physicsClientId=c)
    for body in m.bodies:  # robot.mount_base: search carries its furniture with the base
        if body.carried_by_robot is not None:
            pos, orn = pb.multiplyTransforms(start.base_position, start.base_orientation, *body.carried_by_robot)
            w.set_base_frame(w.bodies[body.name], pos, orn)


def furniture_noise(env: EventTarget, episode: Episode, event: FurnitureNoiseEvent) -> None:
    """The body at its nominal position plus U(−half_width, half_width) per world axis (m)."""
    body, half = env.manifest.body(event.body), np.asarray(event.half_width)
    noise = episode.rng.uniform(-half, half)
    env.world.set_base_frame(env.world.bodies[body.name], tuple(np.asarray(body.position) + noise), body.orientation)


def floor_friction(env: EventTarget, episode: Episode, event: FloorFrictionEvent) -> None:
    """The floor's lateral friction, U(low, high)."""
    friction = float(episode.rng.uniform(event.low, event.high))
    pb.changeDynamics(env.world.ground, -1, lateralFriction=friction, physicsClientId=env.world.client)


def component_reset(env: EventTarget, episode: Episode, event: ComponentResetEvent) -> None:
    """Start the named component's episode."""
    env.components[event.component].reset(episode)


EVENTS: dict[str, Callable[..., None]] = {
    "person_variant": person_variant,
    "reset": component_reset,
    "surface_targets": surface_targets,
    "robot_start": robot_start,
    "furniture_noise": furniture_noise,
    "floor_friction": floor_friction,
}


def bind_events(env: EventTarget, events: Sequence[Event]) -> list[BoundEvent]:
    """The manifest's events bound to ``env``, in order."""
    return [partial(EVENTS[e.event], env, event=e) for e in events]


# -- components without a module of their own ---------------------------------------------------
class Garments(EpisodeComponent):
    """The world's garments: each back to its settled shape in the hand at reset (after the robot's start)."""

    def __init__(self, world: World):
        self.world = world

    def reset(self, episode: Episode) -> None:
        self.world.reset_garments()


class TermMemories(EpisodeComponent):
    """The reward terms' memories (a term class's instance), cleared at reset."""

    def __init__(self, bound: Sequence[BoundTerm]):
        self.bound = list(bound)

    def reset(self, episode: Episode) -> None:
        for term in self.bound:
            term.reset()

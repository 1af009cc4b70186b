"""What a reset does, as ordered events applied with the episode's one random stream
(:func:`reset_events`; the runtime's :mod:`assistive_compiler.runtime.events` applies them)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from .model import ArtifactModel, Vec3


class PersonVariantEvent(ArtifactModel):
    """Draw the episode's person body among ``person.variants``, uniformly (``reset(options=
    {"person_variant": name})`` chooses it instead; the draw is made anyway, so the rest of the
    episode is the seed's); put it in place, park the others, and move the person-attached targets
    to its offsets."""

    event: Literal["person_variant"] = Field("person_variant", description="Event name.")


class ComponentResetEvent(ArtifactModel):
    """Start one runtime component's episode (:class:`~assistive_compiler.runtime.events.EpisodeComponent`):
    ``person`` draws the joint angles and then the impairment, sets and holds them; ``markers``
    puts every marker back; ``reward_terms`` clears the memory of terms that keep some;
    ``particles`` puts them at their settled places in their holder; ``garments`` puts each at its
    settled shape in the hand. Components that draw take the reset's random stream."""

    event: Literal["reset"] = Field("reset", description="Event name.")
    component: Literal["person", "markers", "reward_terms", "particles", "garments"] = Field(
        description="The component whose episode starts."
    )


class SurfaceTargetsEvent(ArtifactModel):
    """Draw each surface target's point on the episode's person (``PersonVariant.surfaces``: a limb,
    a distance along it and an azimuth; ``surface_points``: a link, then one of its points), in
    the variant's order (e.g. the itch, a new spot every episode)."""

    event: Literal["surface_targets"] = Field("surface_targets", description="Event name.")


class RobotStartEvent(ArtifactModel):
    """Draw one of the variant's precomputed ``starts`` uniformly: the robot's base and arm there,
    motor targets at the start, the tools in the hand and furniture carried under the base placed
    with it (no IK)."""

    event: Literal["robot_start"] = Field("robot_start", description="Event name.")


class FurnitureNoiseEvent(ArtifactModel):
    """Move a piece of furniture from its nominal position by a uniform draw per axis."""

    event: Literal["furniture_noise"] = Field("furniture_noise", description="Event name.")
    body: str = Field(description="The furniture body (a name in ``bodies``).")
    half_width: Vec3 = Field(description="Uniform noise half-widths along world x, y, z, m.")


class FloorFrictionEvent(ArtifactModel):
    """Draw the floor's lateral friction coefficient, uniform in [low, high]."""

    event: Literal["floor_friction"] = Field("floor_friction", description="Event name.")
    low: float = Field(description="Lowest friction coefficient.")
    high: float = Field(description="Highest friction coefficient.")


#: One event of a reset, applied in the manifest's order with the episode's one random stream.
Event = Annotated[
    PersonVariantEvent
    | ComponentResetEvent
    | SurfaceTargetsEvent
    | RobotStartEvent
    | FurnitureNoiseEvent
    | FloorFrictionEvent,
    Field(discriminator="event"),
]


def reset_events(
    *,
    surface_targets: bool,
    markers: bool,
    furniture_noise: list[tuple[str, Vec3]],
    floor_friction: tuple[float, float],
    particles: bool,
    garments: bool,
) -> list[Event]:
    """A task's reset, in the order its draws are made: the person variant; the person's joint
    angles and impairment; the surface targets; markers and term memories back; the robot's start;
    each noisy piece of furniture (in body order); the floor's friction; then particles and
    garments, which settle in the hand placed by the start. Parts the task lacks are left out."""
    events: list[Event] = [PersonVariantEvent(), ComponentResetEvent(component="person")]
    if surface_targets:
        events.append(SurfaceTargetsEvent())
    if markers:
        events.append(ComponentResetEvent(component="markers"))
    events += [ComponentResetEvent(component="reward_terms"), RobotStartEvent()]
    events += [FurnitureNoiseEvent(body=body, half_width=noise) for body, noise in furniture_noise]
    events.append(FloorFrictionEvent(low=floor_friction[0], high=floor_friction[1]))
    if particles:
        events.append(ComponentResetEvent(component="particles"))
    if garments:
        events.append(ComponentResetEvent(component="garments"))
    return events

"""What the world holds besides the robot and the person's control: the bodies loaded and their
poses, named targets, particle sets and their rest, marker sets, garments, the camera and the
physics settings (world frame, m, s)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from .model import ArtifactModel, Quat, Vec3


class Body(ArtifactModel):
    """One body loaded into the world."""

    name: str = Field(description="Body name used in references (robot, person_<variant>, spoon, table, ...).")
    kind: Literal["robot", "person", "furniture", "tool"] = Field(description="What the body is.")
    urdf: str = Field(description="URDF path relative to the artifact directory.")
    position: Vec3 = Field(description="Base position, world frame, m.")
    orientation: Quat = Field(description="Base orientation, world frame.")
    fixed_base: bool = Field(description="Loaded with useFixedBase.")
    gravity: float | None = Field(description="Gravity on this body, m/s² along z (None: the world's).")
    friction: float | None = Field(None, description="Lateral friction of every link (None: URDF value).")
    carried_by_robot: tuple[Vec3, Quat] | None = Field(
        None,
        description="Furniture carried under the robot (robot.mount_base: search): its frame (position m, quaternion) in the "
        "robot base frame; every reset places it under the start's base pose. None: it stays at position/orientation.",
    )


class Target(ArtifactModel):
    """A named point on a body (per-variant offsets for the person live in PersonVariant)."""

    body: str = Field(description="Body name ('person' means the active variant).")
    link: str = Field(description="URDF link name.")
    offset: Vec3 = Field(description="Offset in the link frame, m (for the person: the first variant's).")
    show_rgba: tuple[float, float, float, float] | None = Field(None, description="Marker colour for renders.")
    surface: bool = Field(
        False, description="Drawn on a limb surface at every reset (offsets per variant in PersonVariant.surfaces)."
    )


class ParticleSet(ArtifactModel):
    """Small spheres with a lifecycle: active → consumed | lost; first contact with hit_body counts once."""

    name: str = Field(description="Set name.")
    count: int = Field(description="Number of particles.")
    radius: float = Field(description="Radius, m.")
    mass: float = Field(description="Mass of one particle, kg.")
    attach: str = Field(description="Body whose reference frame the start positions are in.")
    attach_link: str = Field(description="URDF link of that body.")
    start_positions: list[Vec3] = Field(description="Settled positions in the attach link frame, m.")
    colors: list[tuple[float, float, float, float]] = Field(description="RGBA per particle.")
    consumed_target: str | None = Field(description="Target that consumes particles.")
    consumed_radius: float = Field(0.0, description="Consumption radius, m.")
    lost_body: str | None = Field(description="Body a particle must stay near.")
    lost_link: str | None = Field(None, description="URDF link of that body (closest-points query).")
    lost_distance: float = Field(0.0, description="Distance beyond which it is lost, m.")
    lost_anchor: Vec3 = Field(
        (0.0, 0.0, 0.0),
        description="A point inside the lost body's collision geometry (lost link frame), m: a particle nearer than lost_distance to it is certainly not lost.",
    )
    hit_body: str | None = Field(description="Body whose first contact with an active particle is a hit.")
    outside_of: Container | None = Field(
        None, description="Particles inside this container are neither consumed nor lost."
    )
    rest: ParticleRest | None = Field(
        None, description="Carry particles at rest in a container instead of simulating them (None: always simulated)."
    )


class ParticleRest(ArtifactModel):
    """Resting particles ride rigidly in their container until its apparent up turns more than
    ``max_turn`` from where they came to rest or tilts more than ``max_tilt`` (see the spec's
    RestInContainer and :mod:`assistive_compiler.runtime.particles`)."""

    container: Container = Field(description="The container that carries them.")
    max_tilt: float = Field(description="Effective tilt above which particles are never carried, radians.")
    max_turn: float = Field(
        description="Turn of the apparent up (container frame) since they came to rest above which they are simulated again, radians."
    )
    max_speed: float = Field(
        description="Mean speed relative to the container below which simulated particles are still, m/s."
    )
    still_steps: int = Field(description="Env steps in a row they must be still before they are carried.")
    carry_at_reset: bool = Field(
        True, description="Carry the settled start positions from the reset on (False: simulated until they rest)."
    )
    near_body: str | None = Field(None, description="Body near which they are simulated even at rest (None: none).")
    near_distance: float = Field(
        0.0, description="Gap between the container's link and near_body below which they are simulated, m."
    )


class MarkerSet(ArtifactModel):
    """Markers on the person (positions per variant in PersonVariant.markers), each cleared once per
    episode when a contact of the clearing tool link with the person lies within ``radius`` of it."""

    name: str = Field(description="Set name.")
    tool: str = Field(description="Tool body that clears markers.")
    tool_link: str = Field(description="URDF link of that tool whose contacts count.")
    radius: float = Field(description="Clearing radius, m.")
    show_rgba: tuple[float, float, float, float] | None = Field(None, description="Marker colour for renders.")


class Container(ArtifactModel):
    """An open vertical cylinder in a tool link's frame from z = 0 to ``height`` (e.g. a cup's inside)."""

    body: str = Field(description="Tool body.")
    link: str = Field(description="URDF link whose frame the cylinder is in.")
    radius: float = Field(description="Radius, m.")
    height: float = Field(description="Height, m.")


class Garment(ArtifactModel):
    """A soft-body garment: its mesh, physics, node sets and how the robot holds it.

    The OBJ's vertices are in the *held frame* (the garment already posed in it); vertex k is
    soft-body node k. ``nodes_in_held`` are the settled node positions in the held frame, where
    every reset puts them (the held frame's world pose is the robot's tool-mount link pose times
    ``grip_position``/``grip_orientation``). The ``anchored`` nodes follow the held frame exactly.
    """

    name: str = Field(description="Body name used in references.")
    obj: str = Field(description="Mesh path relative to the artifact directory (vertices in the held frame, m).")
    parent_link: str = Field(description="Robot link the held frame rides on (URDF name).")
    grip_position: Vec3 = Field(description="Held frame origin in the parent link frame, m.")
    grip_orientation: Quat = Field(description="Held frame orientation in the parent link frame.")
    anchored: list[int] = Field(description="Node indices pinned to the held frame.")
    node_sets: dict[str, list[int]] = Field(description="Named node sets (e.g. opening) → node indices.")
    nodes_in_held: list[Vec3] = Field(description="Settled node positions in the held frame, m (reset starts here).")
    mass: float = Field(description="Total mass, kg.")
    collision_margin: float = Field(description="Collision margin, m.")
    elastic_stiffness: float = Field(description="springElasticStiffness, N/m.")
    damping_stiffness: float = Field(description="springDampingStiffness (all directions), N·s/m.")
    bending_stiffness: float = Field(description="springBendingStiffness, N/m.")
    friction: float = Field(description="Friction coefficient.")
    collides_with: list[str] | None = Field(
        None, description="Bodies ('person' = every variant) the cloth collides with; None: all and the floor."
    )
    rgba: tuple[float, float, float, float] = Field(description="Colour.")


class Camera(ArtifactModel):
    """The camera of renders (world frame, m): from ``eye`` towards ``target``, z up."""

    eye: tuple[float, float, float] = Field((-0.85, -1.35, 1.45), description="Camera position, world frame, m.")
    target: tuple[float, float, float] = Field((-0.12, -0.15, 0.85), description="Point looked at, world frame, m.")
    fov_deg: float = Field(50.0, description="Vertical field of view, degrees.")


class Sim(ArtifactModel):
    """World physics and timing."""

    time_step: float = Field(description="Physics step, s.")
    frame_skip: int = Field(description="Physics steps per env step.")
    episode_steps: int = Field(description="Env steps per episode.")
    gravity: float = Field(description="World gravity along z, m/s².")
    sub_steps: int = Field(description="Solver sub-steps.")
    solver_iterations: int = Field(description="Solver iterations.")
    contact_breaking_threshold: float = Field(0.02, description="Contact breaking threshold, m (see bullet.connect).")

"""The compiled artifact: the contract between the compiler (writes it) and the runtime (reads it).

An artifact is a directory::

    manifest.json          this model, serialised with sorted keys
    urdf/<body>.urdf       one standard URDF per body (person variants: person_<variant>.urdf)

Everything the runtime needs is here, already decided: body files and poses, the person's
posture and which joints move, the robot's arm joints and precomputed start configurations,
tool attachments, targets, particles with their settled positions, the observation, reward
and success programs with references normalised to URDF link and joint names, and what a reset
does, as ordered events. The runtime never
reads YAML and never searches (no IK at reset).

Frames and units: positions in metres in the world frame unless a field says otherwise;
orientations are quaternions (x, y, z, w) as pybullet uses; joint values in radians.
"""

from __future__ import annotations

import hashlib
import json
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    SerializerFunctionWrapHandler,
    ValidationError,
    model_serializer,
    model_validator,
)

from .references import JointGroup, LinkPoint, ParamValue, TargetPoint

#: 2 (2026-11-28): the reset's draws are ``events``; floor friction and furniture noise moved there
#: from ``sim.ground_friction`` and ``Body.position_noise`` (format 1 is read and migrated).
FORMAT_VERSION = 2

#: The agents of a co-optimised task, in order: the robot and the person. They are the manifest's
#: observation groups, the PettingZoo agent ids (``coop``), the RLlib policy ids (``training``) and
#: the parts of a shipped pair (``policies``).
AGENTS = ("robot", "human")

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Body(_Model):
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


class StartState(_Model):
    """One precomputed start: a robot base pose and the arm configuration that puts the tool at a
    (noisy) start pose from it, collision-free."""

    base_position: Vec3 = Field(description="Robot base frame position, world, m.")
    base_orientation: Quat = Field(description="Robot base frame orientation, world.")
    joints: list[float] = Field(description="Arm joint angles in action order, rad.")
    tool_position: Vec3 = Field(description="Where the tool frame (or end effector) starts, world, m.")


class Capsule(_Model):
    """A limb's capsule axis in its link frame: ``start`` at the joint end, ``end``, and the radius."""

    link: str = Field(description="URDF link name.")
    start: Vec3 = Field(description="Axis end at the joint, link frame, m.")
    end: Vec3 = Field(description="Other axis end, link frame, m.")
    radius: float = Field(description="Radius, m.")


class MarkerPoint(_Model):
    """One marker: a point on a limb's surface."""

    link: str = Field(description="URDF link it rides on.")
    offset: Vec3 = Field(description="Position in the link frame, m.")


class SurfacePoint(_Model):
    """One point a surface target may be drawn at: on a link's surface, with its frame."""

    link: str = Field(description="URDF link it is on.")
    offset: Vec3 = Field(description="Position in the link frame, m.")
    normal: Vec3 = Field(description="Outward surface normal, link frame (unit).")
    axis: Vec3 = Field(
        description="A direction along the surface, link frame (unit): a limb's axis away from its joint, else toward +z."
    )


class PersonVariant(_Model):
    """One person body the task may draw at reset."""

    name: str = Field(description="Variant (library person) name.")
    body: str = Field(description="Body name of this variant in ``bodies``.")
    sex: Literal["male", "female"] = Field(description="Body model.")
    mass_kg: float = Field(description="Total mass, kg.")
    standing_height_m: float = Field(description="Standing height at zero joint angles, m.")
    movable_joints: list[str] = Field(description="Joints left revolute (the rest are baked into the URDF).")
    initial_angles: dict[str, float] = Field(description="Initial angle of each movable joint, rad.")
    randomize: dict[str, tuple[float, float]] = Field(description="Per-reset uniform angle ranges, rad.")
    target_offsets: dict[str, Vec3] = Field(description="Offset of each person-attached target in its link, m.")
    surfaces: dict[str, list[Capsule]] = Field(
        default_factory=dict,
        description="Per surface-drawn target: the limbs (capsules, link frame) a reset draws its point on.",
    )
    surface_points: dict[str, list[SurfacePoint]] = Field(
        default_factory=dict,
        description="Per surface-drawn target not drawn on plain capsules (a sphere link such as the "
        "head, or a region): the points a reset draws from, a link uniformly, then a point of it uniformly.",
    )
    markers: dict[str, list[MarkerPoint]] = Field(
        default_factory=dict, description="Per marker set: every marker of this body."
    )
    starts: list[StartState] = Field(description="Robot starts for this variant; reset() draws one.")

    @model_serializer(mode="wrap")
    def _without_empty_additions(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """``surface_points`` came after artifacts were first written: left out while empty, so an
        artifact compiled before it still matches its content hash (runs keep their artifact)."""
        data: dict[str, Any] = handler(self)
        if not data.get("surface_points"):
            data.pop("surface_points", None)
        return data


class _Impairment(_Model):
    """What every impairment choice has: the person joints it acts on and their limits."""

    joints: list[str] = Field(default_factory=list, description="URDF person joints it acts on (empty: none named).")
    limits: dict[str, tuple[float, float]] = Field(
        default_factory=dict, description="Each of those joints' pose-independent URDF limits, rad (lower, upper)."
    )

    @model_serializer(mode="wrap")
    def _without_empty(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """No ``joints`` and ``limits`` keys when it names no joints (the form artifacts were first written in)."""
        data: dict[str, Any] = handler(self)
        for key in ("joints", "limits"):
            if not data.get(key):
                data.pop(key, None)
        return data


class NoImpairment(_Impairment):
    """The person is not impaired."""

    kind: Literal["none"] = Field(description="No impairment.")


class Tremor(_Impairment):
    """Tremor: each joint's target jitters by up to ε, drawn per joint and episode (paper §III-C)."""

    kind: Literal["tremor"] = Field(description="Tremor.")
    amplitude_rad: tuple[float, float] = Field(description="Range ε is drawn from per joint, rad (low, high).")


class Weakness(_Impairment):
    """Weakness: the joints' forces × β, drawn per episode (paper §III-C)."""

    kind: Literal["weakness"] = Field(description="Weakness.")
    strength: tuple[float, float] = Field(description="Range β is drawn from (low, high; 1 = full strength).")


class LimitedRange(_Impairment):
    """Limited range of motion: the joints' limits × γ, drawn per episode (paper §III-C)."""

    kind: Literal["limited_range"] = Field(description="Limited range of motion.")
    scale: tuple[float, float] = Field(description="Range γ is drawn from (low, high).")


Impairment = Annotated[NoImpairment | Tremor | Weakness | LimitedRange, Field(discriminator="kind")]
"""One impairment choice of the task, by its ``kind``."""


class Person(_Model):
    """The person: variants, control and impairments."""

    variants: list[PersonVariant] = Field(description="Bodies one of which is active per episode.")
    policy_joints: list[str] = Field(description="Joints a human policy controls (co-optimisation action order).")
    position_gain: float = Field(description="Gain of policy-controlled joints.")
    max_force: float = Field(description="Force limit of policy-controlled joints, N·m.")
    hold_gain: float = Field(description="Gain holding the non-policy movable joints at their initial angles.")
    hold_force: float = Field(description="Force limit of that hold, N·m.")
    compliant_joints: list[str] = Field(description="Joints held compliantly (static-person task).")
    compliant_gain: float = Field(0.0, description="Gain of the compliant hold.")
    compliant_force: float = Field(0.0, description="Force of the compliant hold, N·m.")
    impairments: list[Impairment] = Field(description="Impairment choices; one is drawn per episode.")
    action_scale: float = Field(
        0.05, description="Policy-joint target change per unit human action per physics step, rad."
    )
    arm_limits: str = Field(
        "analytic",
        description="Pose-dependent arm-limit model of the policy-controlled arm: 'none', 'analytic' (built in) or the path "
        "of an MLP .npz inside the artifact.",
    )
    arm_limits_sha256: str | None = Field(None, description="sha256 of that .npz (so the content hash covers it).")
    self_collision: list[tuple[str, str]] = Field(
        default_factory=list,
        description="Person link pairs (URDF names) that collide with each other; every other pair of the body does not.",
    )


class Drive(_Model):
    """A differential-drive base on a planar chain (see :class:`assistive_compiler.spec.parts.BaseDrive`)."""

    joints: tuple[str, str, str] = Field(description="The x, y (prismatic, m) and yaw (revolute, rad) joints.")
    base_link: str = Field(description="The moving base link (robot_base observations are in its frame).")
    wheel_radius: float = Field(description="Wheel radius, m.")
    wheel_separation: float = Field(description="Distance between the wheels, m.")
    action_scale: float = Field(description="Wheel turn per unit action per physics step, rad.")
    position_gain: float = Field(description="Position gain of the drive joints.")
    max_force: tuple[float, float, float] = Field(description="Force limits of x, y (N) and yaw (N·m).")


class BasePose(_Model):
    """A robot base pose the compile-time search kept (world frame)."""

    position: Vec3 = Field(description="Base position, world frame, m.")
    yaw_rad: float = Field(description="Base yaw about +z, rad.")
    goals_reached: int = Field(description="Reach goals the arm reaches from it without collision.")
    goals: int = Field(description="Reach goals searched for.")
    jlwki: float = Field(
        description="Joint-limit-weighted kinematic isotropy summed over the reached goals (higher: more dexterous)."
    )


class BaseSearch(_Model):
    """The base was placed by the compile-time search (paper §IV): the poses it kept, best first."""

    base_poses: list[BasePose] = Field(description="Kept base poses, best first; reset() draws starts among them.")


class Mounted(_Model):
    """The base is mounted on a furniture piece (no search)."""

    mounted_on: str = Field(description="The furniture the robot is mounted on.")


class Robot(_Model):
    """The robot: which joints act, links by role, control, gripper.

    The action is the drive's two wheel dimensions (when ``drive`` is set), then one per arm joint.
    ``drive``, ``followers`` and ``action_multipliers`` are left out of the JSON when unset, so a
    fixed-base robot's manifest has the same bytes as before they existed."""

    name: str = Field(description="Library robot name.")
    title: str = Field(description="Display name.")
    body: str = Field("robot", description="Body name.")
    arm_joints: list[str] = Field(description="Controlled joints in action order.")
    joint_lower: list[float] = Field(description="Lower limit per arm joint, rad.")
    joint_upper: list[float] = Field(description="Upper limit per arm joint, rad.")
    links: dict[str, str] = Field(description="Semantic link name → URDF link name.")
    action_scale: float = Field(description="Target change per unit action per physics step, rad.")
    position_gain: float = Field(description="Arm position gain.")
    max_force: float = Field(description="Arm force limit, N·m.")
    gripper_joints: list[str] = Field(
        description="The acting hands' finger joints (welded at gripper_position: see welded_joints)."
    )
    gripper_position: list[float] = Field(description="The task's grip: each finger joint's value (rad or m).")
    welded_joints: dict[str, float] = Field(
        default_factory=dict,
        description="Moving joints of the robot's URDF that the task never drives, made fixed in the artifact's robot.urdf at these values (rad or m): fingers at the grip, the rest at 0 (both within the joint's limits).",
    )
    placement: dict[str, Mounted | BaseSearch] = Field(
        default_factory=dict,
        description="How the base was placed: mount, or the search's kept poses with goals reached and JLWKI.",
    )
    action_multipliers: list[float] | None = Field(
        None, description="Per arm joint, a factor on action_scale (None: 1 each)."
    )
    followers: dict[str, str] | None = Field(
        None,
        description="Joints moved with an arm joint (follower -> leader): the same target change every step, the leader's value at start.",
    )
    drive: Drive | None = Field(None, description="The mobile base's drive (None: a fixed base).")

    @model_serializer(mode="wrap")
    def _drop_unset_mobility(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data: dict[str, Any] = handler(self)
        for key in ("action_multipliers", "followers", "drive"):
            if data.get(key) is None:
                data.pop(key, None)
        return data

    @property
    def action_size(self) -> int:
        """Length of the robot's action: two wheel dimensions with a drive, then one per arm joint."""
        return len(self.arm_joints) + (2 if self.drive is not None else 0)


class ToolAttachment(_Model):
    """A tool held in a robot's hand: welded into the robot's URDF, or its own body held by a
    fixed constraint (see :mod:`assistive_compiler.compile.robot`)."""

    body: str = Field(description="Tool body name.")
    parent_link: str = Field(description="Robot link it is attached to.")
    position: Vec3 = Field(description="Tool frame origin in the parent link frame, m.")
    orientation: Quat = Field(description="Tool frame orientation in the parent link frame.")
    links: dict[str, str] = Field(description="Semantic → URDF link names of the tool.")
    welded: bool = Field(
        False,
        description="True: its links are links of the robot's URDF, on a fixed joint '<body>_grip' at this pose, and its "
        "body's urdf is the robot's; False: its own body, held at this pose by a fixed constraint of at most 500 N.",
    )

    @model_serializer(mode="wrap")
    def _drop_unwelded(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """A held tool's manifest entry as before ``welded`` existed, so its artifact keeps its content hash."""
        data: dict[str, Any] = handler(self)
        if not data.get("welded"):
            data.pop("welded", None)
        return data


class Target(_Model):
    """A named point on a body (per-variant offsets for the person live in PersonVariant)."""

    body: str = Field(description="Body name ('person' means the active variant).")
    link: str = Field(description="URDF link name.")
    offset: Vec3 = Field(description="Offset in the link frame, m (for the person: the first variant's).")
    show_rgba: tuple[float, float, float, float] | None = Field(None, description="Marker colour for renders.")
    surface: bool = Field(
        False, description="Drawn on a limb surface at every reset (offsets per variant in PersonVariant.surfaces)."
    )


class ParticleSet(_Model):
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


class ParticleRest(_Model):
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

    @model_serializer(mode="wrap")
    def _without_unset_additions(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """``carry_at_reset`` and ``near_body`` came after artifacts were first written: left out
        while at their defaults, so an artifact compiled before them still matches its content hash."""
        data: dict[str, Any] = handler(self)
        if data.get("carry_at_reset", True):
            data.pop("carry_at_reset", None)
        if data.get("near_body") is None:
            data.pop("near_body", None)
            data.pop("near_distance", None)
        return data


class MarkerSet(_Model):
    """Markers on the person (positions per variant in PersonVariant.markers), each cleared once per
    episode when a contact of the clearing tool link with the person lies within ``radius`` of it."""

    name: str = Field(description="Set name.")
    tool: str = Field(description="Tool body that clears markers.")
    tool_link: str = Field(description="URDF link of that tool whose contacts count.")
    radius: float = Field(description="Clearing radius, m.")
    show_rgba: tuple[float, float, float, float] | None = Field(None, description="Marker colour for renders.")


class Container(_Model):
    """An open vertical cylinder in a tool link's frame from z = 0 to ``height`` (e.g. a cup's inside)."""

    body: str = Field(description="Tool body.")
    link: str = Field(description="URDF link whose frame the cylinder is in.")
    radius: float = Field(description="Radius, m.")
    height: float = Field(description="Height, m.")


class Garment(_Model):
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


class TermUse(_Model):
    """A bound term: registered kind, normalised parameters, weight."""

    name: str = Field(description="Name in info.")
    term: str = Field(description="Registered term kind.")
    category: Literal["reward", "observation", "preference"] = Field(description="Registry category.")
    weight: float = Field(description="Weight (1 for observations).")
    params: dict[str, ParamValue] = Field(
        description="Parameters: references resolved to reference models (assistive_compiler.references), other values as written."
    )
    size: int = Field(1, description="Number of floats it produces (observations).")


class Success(_Model):
    """Success: aggregate of a reward term's value ≥ threshold (absolute)."""

    term: str = Field(description="Reward term name.")
    aggregate: Literal["sum", "max", "min", "last"] = Field(description="Aggregation over the episode.")
    threshold: float = Field(description="Absolute threshold (a fraction when fraction_of is set).")
    fraction_of: str | None = Field(
        None, description="A marker set: the threshold is this fraction of the active variant's markers."
    )


class Camera(_Model):
    """The camera of renders (world frame, m): from ``eye`` towards ``target``, z up."""

    eye: tuple[float, float, float] = Field((-0.85, -1.35, 1.45), description="Camera position, world frame, m.")
    target: tuple[float, float, float] = Field((-0.12, -0.15, 0.85), description="Point looked at, world frame, m.")
    fov_deg: float = Field(50.0, description="Vertical field of view, degrees.")


class Sim(_Model):
    """World physics and timing."""

    time_step: float = Field(description="Physics step, s.")
    frame_skip: int = Field(description="Physics steps per env step.")
    episode_steps: int = Field(description="Env steps per episode.")
    gravity: float = Field(description="World gravity along z, m/s².")
    sub_steps: int = Field(description="Solver sub-steps.")
    solver_iterations: int = Field(description="Solver iterations.")
    contact_breaking_threshold: float = Field(0.02, description="Contact breaking threshold, m (see bullet.connect).")


class PersonVariantEvent(_Model):
    """Draw the episode's person body among ``person.variants``, uniformly (``reset(options=
    {"person_variant": name})`` chooses it instead; the draw is made anyway, so the rest of the
    episode is the seed's); put it in place, park the others, and move the person-attached targets
    to its offsets."""

    event: Literal["person_variant"] = Field("person_variant", description="Event name.")


class ComponentResetEvent(_Model):
    """Start one runtime component's episode (:class:`~assistive_compiler.runtime.events.EpisodeComponent`):
    ``person`` draws the joint angles and then the impairment, sets and holds them; ``markers``
    puts every marker back; ``reward_terms`` clears the memory of terms that keep some;
    ``particles`` puts them at their settled places in their holder; ``garments`` puts each at its
    settled shape in the hand. Components that draw take the reset's random stream."""

    event: Literal["reset"] = Field("reset", description="Event name.")
    component: Literal["person", "markers", "reward_terms", "particles", "garments"] = Field(
        description="The component whose episode starts."
    )


class SurfaceTargetsEvent(_Model):
    """Draw each surface target's point on the episode's person (``PersonVariant.surfaces``: a limb,
    a distance along it and an azimuth; ``surface_points``: a link, then one of its points), in
    the variant's order (e.g. the itch, a new spot every episode)."""

    event: Literal["surface_targets"] = Field("surface_targets", description="Event name.")


class RobotStartEvent(_Model):
    """Draw one of the variant's precomputed ``starts`` uniformly: the robot's base and arm there,
    motor targets at the start, the tools in the hand and furniture carried under the base placed
    with it (no IK)."""

    event: Literal["robot_start"] = Field("robot_start", description="Event name.")


class FurnitureNoiseEvent(_Model):
    """Move a piece of furniture from its nominal position by a uniform draw per axis."""

    event: Literal["furniture_noise"] = Field("furniture_noise", description="Event name.")
    body: str = Field(description="The furniture body (a name in ``bodies``).")
    half_width: Vec3 = Field(description="Uniform noise half-widths along world x, y, z, m.")


class FloorFrictionEvent(_Model):
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


class ScriptWaypoint(_Model):
    """One waypoint of the scripted baseline: where the moved point goes next (world frame, m)."""

    to: TargetPoint | LinkPoint = Field(description="The point it heads for.")
    offset_m: Vec3 = Field(description="Offset from that point, world frame, m.")
    tolerance_m: float = Field(description="Reached within this distance, m (0: never; a last waypoint to hold).")
    normal_offset_m: float = Field(0.0, description="Offset along a surface target's outward normal, m.")
    axis_offset_m: float = Field(0.0, description="Offset along a surface target's limb axis, m.")
    rpy_rad: Vec3 | None = Field(
        description="Orientation of the end effector to hold (roll, pitch, yaw, rad), or none."
    )
    face_normal_within_rad: float | None = Field(
        description="Turn the tool towards the surface normal by at most this much, rad, or none."
    )
    step_m: float | None = Field(None, description="Straight-line look-ahead per step, m (none: straight to the goal).")
    face_normal_level: bool = Field(False, description="Turn about the vertical only (keep the tool level).")
    turn_step_rad: float | None = Field(None, description="Most the tool turns per step, rad (none: no limit).")

    @model_serializer(mode="wrap")
    def _without_unset_additions(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """``step_m``, ``face_normal_level`` and ``turn_step_rad`` are left out when unset (the form
        artifacts were first written in)."""
        data: dict[str, Any] = handler(self)
        for key in ("step_m", "turn_step_rad"):
            if data.get(key) is None:
                data.pop(key, None)
        if not data.get("face_normal_level"):
            data.pop("face_normal_level", None)
        return data


class Script(_Model):
    """The scripted baseline's script for one arm: the point it moves through its waypoints."""

    move: TargetPoint | LinkPoint = Field(description="The point moved (a tool's tip, the end effector).")
    waypoints: list[ScriptWaypoint] = Field(description="Waypoints in order.")
    repeat_from: int | None = Field(description="After the last waypoint, go on from this one (none: hold the last).")
    ik_damping: dict[str, float] | None = Field(None, description="IK damping of some arm joints, by URDF name.")
    left: Script | None = Field(
        None, description="A two-arm robot's left arm's own script (this one is the right arm's)."
    )

    @model_serializer(mode="wrap")
    def _without_unset(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """``ik_damping`` and ``left`` are left out when unset."""
        data: dict[str, Any] = handler(self)
        for key in ("ik_damping", "left"):
            if data.get(key) is None:
                data.pop(key, None)
        return data


class Manifest(_Model):
    """The whole artifact description."""

    format_version: int = Field(FORMAT_VERSION, description="Artifact format version.")
    task: str = Field(description="Task name.")
    title: str = Field(description="Task title.")
    robot_name: str = Field(description="Robot compiled for.")
    gym_id: str = Field(
        description="Gymnasium id that makes this (task, robot): a shipped task's own "
        "(assistive_compiler/FeedingJaco-v1), else assistive_compiler/Task-v1 (with spec= and robot=)."
    )
    input_hash: str = Field(description="sha256 of every input (spec files, parts, templates, compiler source).")
    content_hash: str = Field(
        "",
        description="sha256 of the output files (URDFs and the manifest minus this field and input_hash): "
        "what was compiled, whichever compiler source compiled it.",
    )
    sources: list[str] = Field(description="Spec and part files this was compiled from.")
    sim: Sim = Field(description="Physics settings: time step, frame skip, solver, gravity, episode length.")
    bodies: list[Body] = Field(
        description="Every URDF body the world loads (robot, furniture, tools, each person variant), placed."
    )
    person: Person = Field(description="The person: variants, holds, impairments, policy joints, limits.")
    robot: Robot = Field(description="The robot: action joints and scaling, named links, start configurations.")
    tools: list[ToolAttachment] = Field(description="Tools held by the robot: which link, where in it.")
    targets: dict[str, Target] = Field(description="Named target points (a link and an offset), by name.")
    particles: list[ParticleSet] = Field(description="Particle sets (food, water): size, mass, where they start.")
    markers: list[MarkerSet] = Field(default_factory=list, description="Marker sets on the person.")
    joint_groups: dict[str, JointGroup] = Field(
        description="Joint groups by reference name (``robot.arm``, ``person.head``)."
    )
    observations: dict[str, list[TermUse]] = Field(description="Observation features per agent, in order.")
    reward: list[TermUse] = Field(description="Reward terms including preference costs.")
    success: Success = Field(description="The success criterion: which term, how aggregated, the threshold.")
    garments: list[Garment] = Field(
        default_factory=list, description="Soft-body garments (their presence makes the world a deformable one)."
    )
    scripted: Script | None = Field(
        None, description="The scripted baseline's script for this robot (none: no baseline)."
    )
    camera: Camera = Field(default_factory=lambda: Camera(), description="The task's camera for this robot (renders).")
    events: list[Event] = Field(
        description="What ``reset()`` does, in order, with the episode's one random stream: the draws "
        "(person variant, surface targets, robot start, furniture noise, floor friction) and the "
        "components' episode starts (:func:`reset_events`)."
    )
    #: The manifest as its file holds it, when that was an older format (migrated on reading):
    #: its content hash covers that form.
    _as_written: dict[str, Any] | None = PrivateAttr(None)

    @model_validator(mode="before")
    @classmethod
    def _migrate(cls, data: Any) -> Any:
        """Format 1 (before 2026-11-28) had no ``events``: build the ones its runtime applied."""
        if isinstance(data, dict) and data.get("format_version") == 1:
            data = _format_1_migrated(data)
        return data

    @property
    def label(self) -> str:
        """A name for logs and plot titles: the shipped task's id (``assistive_compiler/FeedingJaco-v1``),
        or ``<task> for <robot>`` for any other spec (whose id, ``assistive_compiler/Task-v1``, is shared)."""
        from .gym_ids import TASK_ID

        return self.gym_id if self.gym_id != TASK_ID else f"{self.task} for {self.robot_name}"

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(name)

    def to_json(self) -> str:
        return json.dumps(self.model_dump(mode="json"), indent=1, sort_keys=True) + "\n"

    def hash_of(self, artifact_dir: str | Path, *, with_input_hash: bool = False) -> str:
        """sha256 of the body files under ``artifact_dir`` and this manifest (``content_hash`` and
        ``input_hash`` empty): what ``content_hash`` records when the artifact is as compiled. The
        same content compiled by another version of the compiler source has the same hash, so a
        run can be resumed across a change that compiles its task to the same files.
        ``with_input_hash``: the hash as artifacts written before 2026-11-28 recorded it (the
        manifest with its input hash, which covers the compiler source)."""
        return self._hash(self._body_bytes(artifact_dir), with_input_hash=with_input_hash)

    def _body_bytes(self, artifact_dir: str | Path) -> bytes:
        return b"".join(Path(artifact_dir, b.urdf).read_bytes() for b in sorted(self.bodies, key=lambda b: b.urdf))

    def _hash(self, files: bytes, *, with_input_hash: bool, as_written: bool = False) -> str:
        """``as_written``: of the manifest in the form its file holds (an older format's), not today's."""
        blank = {"content_hash": ""} if with_input_hash else {"content_hash": "", "input_hash": ""}
        if as_written and self._as_written is not None:
            text = json.dumps(self._as_written | blank, indent=1, sort_keys=True) + "\n"
        else:
            text = self.model_copy(update=blank).to_json()
        return hashlib.sha256(files + text.encode()).hexdigest()

    def damage(self, artifact_dir: str | Path) -> str | None:
        """What is wrong with the files of the artifact at ``artifact_dir`` (a missing, truncated or
        edited URDF), or None when they are exactly as compiled."""
        for b in self.bodies:
            path = Path(artifact_dir, b.urdf)
            if not path.is_file():
                return f"{path}: missing"
            try:
                ET.parse(path)
            except ET.ParseError as exc:
                return f"{path}: not complete URDF XML ({exc}); truncated or edited?"
        if not self.content_hash:
            return None
        files = self._body_bytes(artifact_dir)  # read once; the older hash only when the current one differs
        if self.content_hash != self._hash(
            files, with_input_hash=False, as_written=True
        ) and self.content_hash != self._hash(files, with_input_hash=True, as_written=True):
            return f"{artifact_dir}: files differ from what was compiled (the manifest's content hash does not match)"
        return None

    @classmethod
    def read(cls, artifact_dir: str | Path, verify: bool = False) -> Manifest:
        """The manifest of the artifact at ``artifact_dir``; with ``verify``, a :class:`SpecError`
        naming what is damaged when its files are not as compiled (see :meth:`damage`)."""
        from .errors import SpecError

        path = Path(artifact_dir, "manifest.json")
        if not path.is_file():
            raise SpecError.at(
                str(artifact_dir), "not a compiled artifact (no manifest.json); compile a spec into it first"
            )
        try:
            text = path.read_text()
            manifest = cls.model_validate_json(text)  # pydantic's own messages for malformed JSON
            written = json.loads(text)
            if manifest.format_version != written.get("format_version"):
                manifest._as_written = written
        except (ValueError, UnicodeDecodeError) as exc:
            raise SpecError.at(
                str(path), f"not a readable manifest ({_first_problem(exc)}); recompile with 'compile --force'"
            ) from None
        problem = manifest.damage(artifact_dir) if verify else None
        if problem:
            raise SpecError.at(
                str(artifact_dir),
                f"damaged artifact: {problem}; recompile it (assistive-compiler compile SPEC --out {artifact_dir} --force)",
            )
        return manifest


def _first_problem(exc: Exception) -> str:
    """One line naming what made a manifest unreadable: the first field pydantic refused, by its
    dotted path, with pydantic's reason (and how many more there are); else the error's first line."""
    if isinstance(exc, ValidationError) and exc.errors():
        errors = exc.errors()
        first = errors[0]
        where = ".".join(str(part) for part in first["loc"]) or "the top level"
        more = f", and {len(errors) - 1} more" if len(errors) > 1 else ""
        return f"{where}: {first['msg']}{more}"
    return str(exc).splitlines()[0]


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


def _format_1_migrated(data: dict[str, Any]) -> dict[str, Any]:
    """A format-1 manifest's data in format 2: the events its runtime applied at every reset, from
    ``sim.ground_friction`` and the furniture's ``position_noise``, which move into them."""
    sim = dict(data["sim"])
    low, high = sim.pop("ground_friction")
    bodies, noisy = [], []
    for body in data["bodies"]:
        body = dict(body)
        noise = tuple(body.pop("position_noise", (0.0, 0.0, 0.0)))
        if body["kind"] == "furniture" and any(noise):
            noisy.append((body["name"], noise))
        bodies.append(body)
    variants = data["person"]["variants"]
    events = reset_events(
        surface_targets=any(v.get("surfaces") or v.get("surface_points") for v in variants),
        markers=bool(data.get("markers")),
        furniture_noise=noisy,
        floor_friction=(low, high),
        particles=bool(data["particles"]),
        garments=bool(data.get("garments")),
    )
    return data | {
        "format_version": FORMAT_VERSION,
        "sim": sim,
        "bodies": bodies,
        "events": [e.model_dump(mode="json") for e in events],
    }

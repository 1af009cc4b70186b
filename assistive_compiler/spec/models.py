"""The task spec language: pydantic models, strict, one ``description=`` per field.

A task spec (``specs/tasks/*.yaml``) says *what* the task is — the scene, the person, the robot's
role, tools, named targets, particles, observations, reward terms, preferences and success — and
never *how* to simulate it. Units are in field names (``_m``, ``_deg``, ``_kg``, ``_s``, ``_n``)
or descriptions. World frame: Z up, gravity along −Z; the seated person faces −Y and their right
side is −X (the reference's convention).

References between parts are plain strings checked by :mod:`assistive_compiler.resolve`:

* a **body**: ``robot``, ``person``, a furniture name, a tool name, a particle-set name;
* a **link** of a body: ``body.semantic_link`` (``person.head``, ``robot.end_effector``,
  ``spoon.tip``); a bare body name means the body's reference link;
* a **target**: a name declared under ``targets:`` (``mouth``);
* a **joint group**: ``robot.arm`` or ``person.<group>`` (``person.head``, ``person.right_arm``).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

Name = Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*$", max_length=64)]
Ref = Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*(\.[a-z][a-z0-9_]*)?$", max_length=129)]
Vec3 = tuple[float, float, float]
Rgba = tuple[
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
    Annotated[float, Field(ge=0, le=1)],
]


class Strict(BaseModel):
    """Base of every spec model: unknown keys are errors, NaN and infinities are refused."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True, populate_by_name=False)


# --------------------------------------------------------------------------------------------
# Random quantities


class Uniform(Strict):
    """A value drawn uniformly from [low, high] at every reset."""

    uniform: tuple[float, float] = Field(description="Bounds [low, high] of a uniform draw; low ≤ high.")

    @model_validator(mode="after")
    def _ordered(self) -> "Uniform":
        low, high = self.uniform
        if low > high:
            raise ValueError(f"@uniform: bounds are reversed: low {low:g} > high {high:g}; write [low, high]")
        return self


Scalar = Union[float, Uniform]
"""A fixed number or ``{uniform: [low, high]}`` re-drawn at every reset."""


def describe(value: Scalar) -> str:
    """``1.5`` or ``U(0.2, 0.9)`` for messages."""
    low, high = scalar_bounds(value)
    return f"{low:g}" if low == high else f"U({low:g}, {high:g})"


def scalar_bounds(value: Scalar) -> tuple[float, float]:
    """The smallest and largest value a :data:`Scalar` can take."""
    if isinstance(value, Uniform):
        return value.uniform
    return (float(value), float(value))


# --------------------------------------------------------------------------------------------
# Simulation


class Solver(Strict):
    """Bullet constraint-solver settings (``setPhysicsEngineParameter``)."""

    sub_steps: int = Field(0, ge=0, le=64, description="numSubSteps: extra sub-steps per physics step (0 = none).")
    iterations: int = Field(50, ge=1, le=1000, description="numSolverIterations per physics step.")
    contact_breaking_threshold_m: float = Field(
        0.02, gt=0, le=0.1,
        description="Distance (m) a cached contact point may drift before Bullet drops it (Bullet's default 0.02). "
                    "Small rolling particles pile up stale copies of their one contact under the default, each a "
                    "solver row: 0.002 cuts Feeding's physics by 14% and Drinking's by 21%. Stale points also widen "
                    "where a contact is reported (Bed Bathing's wiping counts them), so tasks keep the default "
                    "unless they need the speed.")


class Ground(Strict):
    """The floor (its top face at z = 0)."""

    friction: Scalar = Field(
        default_factory=lambda: Uniform(uniform=(0.025, 0.5)),
        description="Lateral friction coefficient of the floor (the reference re-draws U(0.025, 0.5) every reset).",
    )

    @field_validator("friction")
    @classmethod
    def _nonnegative(cls, v: Scalar) -> Scalar:
        if scalar_bounds(v)[0] < 0:
            raise ValueError("friction must be ≥ 0")
        return v


class Sim(Strict):
    """Timing and world physics. The paper: 0.02 s physics steps, 5 per action (10 Hz), 200 actions."""

    time_step_s: float = Field(0.02, gt=0, le=0.1, description="Physics time step in seconds.")
    frame_skip: int = Field(5, ge=1, le=100, description="Physics steps per environment step (action).")
    episode_steps: int = Field(200, ge=1, le=100_000, description="Environment steps per episode (then truncated).")
    gravity_mps2: float = Field(-9.81, ge=-20, le=0, description="World gravity along +Z in m/s² (negative: downwards).")
    solver: Solver = Field(default_factory=Solver, description="Constraint-solver settings.")
    ground: Ground = Field(default_factory=Ground, description="The floor.")


# --------------------------------------------------------------------------------------------
# Scene


class FurnitureUse(Strict):
    """One piece of furniture or a free object placed in the scene, by library part name."""

    part: Name = Field(description="Furniture part from the library (specs/furniture/<part>.yaml).")
    position_m: Vec3 = Field((0.0, 0.0, 0.0), description="Position of the part's frame in the world, metres.")
    rpy_deg: Vec3 = Field((0.0, 0.0, 0.0), description="Orientation (roll, pitch, yaw) in degrees, world frame.")
    position_noise_m: Vec3 = Field(
        (0.0, 0.0, 0.0), description="Half-width of a uniform per-axis offset re-drawn at every reset, metres."
    )
    static: bool | None = Field(None, description="Fixed in the world (None: the part's default).")
    friction: float | None = Field(None, ge=0, description="Lateral friction override (None: the part's value).")
    params: dict[str, float | int | str | bool] = Field(
        default_factory=dict, description="Template parameters of the part (e.g. a wheelchair's robot_mount side)."
    )
    only_when_mounted: bool = Field(
        False,
        description="In the scene only when the task's robot is mounted on it (it must be robot.mount_on and the robot "
        "mountable): a nightstand that carries Jaco is absent for a PR2 standing on the floor. Nothing else in the spec may "
        "refer to such furniture.",
    )

    @field_validator("position_noise_m")
    @classmethod
    def _noise_nonnegative(cls, v: Vec3) -> Vec3:
        if any(x < 0 for x in v):
            raise ValueError("noise half-widths must be ≥ 0")
        return v


class Scene(Strict):
    """Furniture and objects, keyed by the name specs use to refer to them."""

    furniture: dict[Name, FurnitureUse] = Field(default_factory=dict, description="Placed furniture by name.")


# --------------------------------------------------------------------------------------------
# Person


def _in_unit_interval(value: Scalar, name: str) -> Scalar:
    """Check a fixed or random factor lies in (0, 1]."""
    low, high = scalar_bounds(value)
    if low <= 0 or high > 1:
        raise ValueError(f"{name} must lie in (0, 1], got {describe(value)}")
    return value


class Tremor(Strict):
    """Tremor: each affected joint's target oscillates by ±ε, the sign flipping every env step."""

    kind: Literal["tremor"] = Field(description="Impairment kind.")
    amplitude_deg: Scalar = Field(
        default_factory=lambda: Uniform(uniform=(0.0, 20.0)),
        description="Per-joint amplitude ε in degrees (paper: U(0°, 20°)), drawn per joint per episode.",
    )
    joints: list[Ref] = Field(default_factory=lambda: ["person.policy"], description="Joint groups affected.")


class Weakness(Strict):
    """Weakness: joint torque limits are scaled by a strength β."""

    kind: Literal["weakness"] = Field(description="Impairment kind.")
    strength: Scalar = Field(
        default_factory=lambda: Uniform(uniform=(0.25, 1.0)),
        description="Strength β ∈ (0, 1] multiplying joint torque limits (paper: U(0.25, 1)).",
    )
    joints: list[Ref] = Field(default_factory=lambda: ["person.policy"], description="Joint groups affected.")

    _range = field_validator("strength")(lambda v: _in_unit_interval(v, "strength"))


class LimitedRange(Strict):
    """Limited range of motion: arm and head joint limits are scaled by γ."""

    kind: Literal["limited_range"] = Field(description="Impairment kind.")
    scale: Scalar = Field(
        default_factory=lambda: Uniform(uniform=(0.5, 1.0)),
        description="Range scale γ ∈ (0, 1] applied to joint limits (paper: U(0.5, 1)).",
    )
    joints: list[Ref] = Field(
        default_factory=lambda: ["person.right_arm", "person.left_arm", "person.head"], description="Joint groups affected."
    )

    _range = field_validator("scale")(lambda v: _in_unit_interval(v, "scale"))


class NoImpairment(Strict):
    """No impairment."""

    kind: Literal["none"] = Field(description="Impairment kind.")


Impairment = Annotated[Union[NoImpairment, Tremor, Weakness, LimitedRange], Field(discriminator="kind")]


class Impairments(Strict):
    """Which impairment a person has; one choice is drawn at every reset."""

    choices: list[Impairment] = Field(
        default_factory=lambda: [NoImpairment(kind="none")],
        min_length=1,
        description="Impairments to draw from uniformly at each reset (one entry = a fixed impairment).",
    )


class CompliantHold(Strict):
    """Joints held at their initial pose by a weak position controller (they yield to contact)."""

    joints: list[Ref] = Field(description="Joint groups held compliantly, e.g. person.right_arm.")
    max_force_nm: float = Field(gt=0, description="Motor force limit, N·m, before strength scaling.")
    position_gain: float = Field(gt=0, le=1, description="Position gain of the hold.")


class PersonControl(Strict):
    """How the person's joints move. Joints not named here are static: baked into the URDF."""

    policy_joints: list[Ref] = Field(
        default_factory=list, description="Joint groups a human policy controls in co-optimisation (e.g. person.head)."
    )
    compliant: CompliantHold | None = Field(None, description="Joints held compliantly in the static-person task.")
    position_gain: float = Field(0.05, gt=0, le=1, description="Position gain of policy-controlled joints.")
    max_force_nm: float = Field(1.0, gt=0, description="Force limit of policy-controlled joints, N·m.")
    action_scale_rad: float = Field(
        0.05, gt=0, le=1, description="Policy-joint target change per unit human action per physics step, radians (the reference: 0.05)."
    )
    arm_limits: str = Field(
        "analytic",
        description="Pose-dependent shoulder-elbow limits enforced after every physics step on the arm whose shoulder (3 axes) "
        "and elbow are policy joints (the right one if both; paper §III-C): 'analytic' (the built-in model), 'none', or the "
        "path of a .npz MLP (arrays W0, b0, W1, b1, ...; relative to the spec file that says it).",
    )

    @field_validator("arm_limits")
    @classmethod
    def _arm_limit_model(cls, v: str) -> str:
        if v in ("none", "analytic") or (v.lower().endswith(".npz") and len(v) > 4):
            return v
        from ..errors import did_you_mean

        raise ValueError(f"must be 'analytic', 'none' or the path of a .npz file, got '{v}'{did_you_mean(v, ['analytic', 'none'])}")


class Settle(Strict):
    """Compile-time settling, as the reference does at every reset in the bed tasks: the body with a
    free base and limp joints (each angle perturbed by U(±joint_noise_rad)) falls for ``steps``
    physics steps under ``gravity_mps2`` onto the furniture; the settled base pose and joint angles
    are then stored (static joints baked at them), so reset() does not settle again."""

    steps: int = Field(100, ge=1, le=5000, description="Physics steps to settle (the reference: 100 = 2 s).")
    gravity_mps2: float = Field(-1.0, ge=-20, lt=0, description="Gravity while settling, m/s² (the reference: −1).")
    joint_noise_rad: float = Field(0.1, ge=0, le=1, description="Half-width of the uniform noise on every joint angle, rad.")
    friction: float | None = Field(None, ge=0, description="Friction of the furniture while settling (the reference: 5); None keeps it.")
    then: "SettleStage | None" = Field(
        None, description="A second compile-time stage after settling (e.g. an arm dropped to hang off the bed, paper §III-B)."
    )


class StageHold(Strict):
    """The weak position hold of a settle stage's dynamic joints (towards the stage's start angles)."""

    max_force_nm: float = Field(gt=0, description="Motor force limit, N·m (the reference's arm manipulation: 0.01 × strength 1).")
    position_gain: float = Field(gt=0, le=1, description="Position gain (the reference: 0.05).")


class SettleStage(Strict):
    """A compile-time stage after settling: the settled base is fixed and every joint is held at its
    settled angle, except the ``dynamic`` joint groups, which are first set to ``joints_deg`` (the
    others keep theirs) and then move freely under ``gravity_mps2`` and a weak ``hold`` for
    ``steps`` physics steps. The resulting angles are stored like the settled ones."""

    joints_deg: dict[Name, float] = Field(default_factory=dict, description="Joint angles set before the stage, degrees by joint name.")
    dynamic: list[Ref] = Field(min_length=1, description="Person joint groups left free during the stage, e.g. person.right_arm.")
    hold: StageHold | None = Field(None, description="Weak hold of the dynamic joints (None: limp).")
    gravity_mps2: float = Field(-9.81, ge=-20, lt=0, description="Gravity during the stage, m/s².")
    steps: int = Field(100, ge=1, le=5000, description="Physics steps of the stage (the reference: 100).")
    friction: float | None = Field(None, ge=0, description="Friction of the furniture during the stage (the reference: 0.3); None keeps the settle's.")


class Placement(Strict):
    """Where the person's base (chest) goes."""

    seated_on: Name | None = Field(
        None, description="Furniture to sit on: the body is lowered onto the part's seat surface at its seat frame."
    )
    position_m: Vec3 | None = Field(None, description="Explicit chest position in the world, metres.")
    rpy_deg: Vec3 = Field((0.0, 0.0, 0.0), description="Chest orientation (roll, pitch, yaw) in degrees.")
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Added to the seat-derived position, metres.")
    settle: "Settle | None" = Field(
        None, description="Let the limp body fall onto the furniture at compile time and keep the settled pose (supine people)."
    )

    @model_validator(mode="after")
    def _one_way(self) -> "Placement":
        if (self.seated_on is None) == (self.position_m is None):
            raise ValueError("give exactly one of 'seated_on' (a furniture name) or 'position_m'")
        return self


class Person(Strict):
    """The person being helped: who (library people), posture, what moves, impairments."""

    variants: list[Name] = Field(
        min_length=1,
        description="People from the library (specs/people/<name>.yaml); one is drawn at every reset.",
    )
    posture: Literal["seated", "supine", "standing"] = Field(description="Named base posture.")
    placement: Placement = Field(description="Where the chest goes.")
    joints_deg: dict[Name, float] = Field(default_factory=dict, description="Joint angles in degrees by joint name.")
    randomize_deg: dict[Name, Uniform] = Field(
        default_factory=dict, description="Per-reset random joint angles in degrees by joint name (replace joints_deg)."
    )
    gravity_mps2: float | None = Field(
        None, ge=-20, le=0, description="Gravity acting on the person, m/s² (None: the world's). 0 = floats in place."
    )
    control: PersonControl = Field(default_factory=PersonControl, description="Which joints move and how.")
    impairments: Impairments = Field(default_factory=Impairments, description="Impairments drawn per reset.")


# --------------------------------------------------------------------------------------------
# Robot and tools


class RobotControl(Strict):
    """Joint-position-delta control of the robot arm, as in the paper."""

    action_scale_rad: float = Field(
        0.05, gt=0, le=1, description="Joint target change per unit action per physics step, radians."
    )
    position_gain: float = Field(0.05, gt=0, le=1, description="Position gain of the arm motors.")
    max_force_nm: float = Field(1.0, gt=0, description="Force limit of the arm motors, N·m (gravity is compensated).")


class StartGoal(Strict):
    """The pose the held tool (or, without a tool, the end effector) starts in at every reset.

    Stated for the tool, not the end effector, so one task fits every robot: the compiler turns it
    into each robot's end-effector pose through that robot's grip, and solves IK at compile time.
    """

    tool_position_m: Vec3 = Field(description="Tool frame position in the world, metres.")
    tool_rpy_deg: Vec3 = Field((0.0, 0.0, 0.0), description="Tool frame orientation (roll, pitch, yaw), degrees.")
    noise_m: float = Field(0.05, ge=0, le=0.5, description="Half-width of a uniform per-axis start noise, metres.")
    samples: int = Field(
        8, ge=1, le=256, description="Noisy start poses solved at compile time; reset() picks one (no IK at reset)."
    )


class Goal(Strict):
    """A pose the robot should be able to reach from its base: the tool (or, without a tool, the end
    effector) at a point, optionally with the tool's start orientation."""

    point: Ref = Field(description="Target or link the goal is at, e.g. mouth.")
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Offset from that point, world frame, metres.")
    oriented: bool = Field(False, description="Also reach the tool's start orientation (else position only).")
    required: bool = Field(False, description="A base pose that cannot reach this goal is discarded.")
    arm: Literal["right", "left"] | None = Field(
        None, description="Which arm reaches it when the robot acts with both arms (robot.arm: both); None: the right "
        "(acting) arm. A one-arm robot reaches every goal with its arm."
    )


class BaseSearch(Strict):
    """Compile-time base-pose optimisation for robots standing on the floor (paper §III-D): sample base
    poses, solve IK to each goal with collision checks, keep the poses that reach the most goals,
    ties broken by joint-limit-weighted kinematic isotropy (JLWKI). The start pose is always a
    required, oriented goal. Deterministic and bounded: exactly ``attempts`` samples."""

    origin_m: Vec3 = Field((-0.85, -0.4, 0.0), description="Anchor of the sampling box in the world (x, y), m; z is ignored.")
    x_range_m: tuple[float, float] = Field((-0.5, 0.0), description="Uniform x offset from the anchor, m.")
    y_range_m: tuple[float, float] = Field((-0.5, 0.5), description="Uniform y offset from the anchor, m.")
    yaw_deg: float = Field(0.0, ge=-360, le=360, description="Base yaw before noise, degrees.")
    yaw_noise_deg: float = Field(30.0, ge=0, le=180, description="Half-width of the uniform yaw noise, degrees.")
    attempts: int = Field(100, ge=1, le=5000, description="Base poses sampled (the paper: 100).")
    keep: int = Field(4, ge=1, le=32, description="Best base poses stored in the artifact; reset() picks among them.")
    goals: list[Goal] = Field(default_factory=list, description="Goals scored besides the start pose.")


class PerRobot(Strict):
    """Task settings that differ per robot (the reference's per-task robot tables)."""

    base_offset_m: Vec3 | None = Field(None, description="Base position offset from the mount or the search anchor, m (the reference's toc_base_pos_offset).")
    start: StartGoal | None = Field(None, description="This robot's start pose, replacing robot.start (e.g. a one-arm robot's single start in a two-arm task).")
    base_search: BaseSearch | None = Field(
        None, description="This robot's base search, replacing robot.base_search (e.g. a robot that reaches a goal only "
        "part of the time, where the task requires it of the others)."
    )


class RobotRole(Strict):
    """What the robot does in this task. The robot itself is chosen at compile time (--robot)."""

    default: Name = Field(description="Robot used when none is given (e.g. jaco).")
    supported: list[Name] = Field(min_length=1, description="Robots this task is written for.")
    arm: Literal["right", "left", "both"] = Field(description="Which arm acts (single-arm robots use their only arm).")
    mount_on: Name | None = Field(
        None, description="Furniture that mounts robots able to be mounted (e.g. Jaco on the wheelchair)."
    )
    mount_base: Literal["furniture", "search"] = Field(
        "furniture",
        description="Where a mounted robot's base goes. 'furniture': on the mount furniture's mount_link where the scene "
        "places it, plus per_robot.base_offset_m (Jaco on the wheelchair). 'search': base_search chooses the base pose, as "
        "for a robot standing on the floor but at the mount link's height, and the furniture is carried under the chosen "
        "base (the mount link on the base frame; its scene pose is then not given) — the reference's nightstand beside a bed.",
    )
    gravity_mps2: float | None = Field(0.0, ge=-20, le=0, description="Gravity on the robot (0: compensated).")
    control: RobotControl = Field(default_factory=RobotControl, description="Arm control.")
    start: StartGoal = Field(description="Start pose of the tool of the acting arm (the right arm when arm is 'both').")
    start_left: StartGoal | None = Field(
        None, description="Start pose of the left arm's tool when arm is 'both' and the robot has two arms (one-arm robots "
        "use start, or per_robot.<robot>.start)."
    )
    base_search: BaseSearch = Field(default_factory=BaseSearch, description="Base placement of robots that are not mounted.")
    per_robot: dict[Name, PerRobot] = Field(default_factory=dict, description="Per-robot settings by robot name.")

    def search_for(self, robot: str) -> BaseSearch:
        """The base search ``robot`` uses: its per_robot one if it has one, else the task's."""
        own = self.per_robot.get(robot)
        return own.base_search if own is not None and own.base_search is not None else self.base_search

    @model_validator(mode="after")
    def _default_supported(self) -> "RobotRole":
        if self.default not in self.supported:
            from ..errors import did_you_mean

            raise ValueError(f"@default: default robot '{self.default}' is not in supported {self.supported}{did_you_mean(self.default, self.supported)}")
        if self.start_left is not None and self.arm != "both":
            raise ValueError(f"@start_left: start_left is the left arm's start in a task acting with both arms, but this task's arm is '{self.arm}'; remove it or set arm: both")
        return self


class ToolUse(Strict):
    """A tool the robot holds, rigidly attached to the robot's tool-mount link."""

    part: Name = Field(description="Tool part from the library (specs/tools/<part>.yaml).")
    hand: Literal["right", "left"] = Field(description="Which hand holds it (single-arm robots: their only hand).")
    gravity_mps2: float | None = Field(0.0, ge=-20, le=0, description="Gravity on the tool (0: weightless).")
    mass_kg: float | None = Field(None, gt=0, description="Mass override in kg (None: the part's mass).")
    grip: Name | None = Field(
        None, description="Which of the robot part's grips (grips: in specs/robots/<robot>.yaml) holds this tool; default "
        "the tool's part name. A new tool shaped like a shipped one can reuse its grip (e.g. grip: scratcher).",
    )
    one_arm_same_as: Name | None = Field(
        None, description="On a robot acting with one arm (which serves as both hands), this tool is the named tool, held "
        "in the other hand: one body that both names refer to (the reference's single-arm arm manipulation, paper §III-B). "
        "Two-arm robots acting with both arms hold both tools.",
    )


# --------------------------------------------------------------------------------------------
# Targets and particles


class Target(Strict):
    """A named point attached to a link: e.g. the mouth is the head link plus an offset; or a point
    drawn on a limb's surface at every reset (e.g. an itch on the right arm)."""

    link: Ref | None = Field(None, description="The link it is attached to, e.g. person.head (or give surface_of).")
    surface_of: list[Ref] = Field(
        default_factory=list,
        description="Person limbs (capsule links, e.g. person.right_shoulder = the upper arm) to draw the point on at "
        "every reset: a limb uniformly, then the distance from its joint U(r, L) along the capsule and the azimuth "
        "U(0, 2π) (the reference's itch target).",
    )
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Offset in the link frame, metres.")
    offset_by_variant: dict[Name, Vec3] = Field(
        default_factory=dict, description="Per person-variant offsets replacing offset_m (e.g. female mouth)."
    )
    show_rgba: Rgba | None = Field(None, description="Draw a small sphere there in renders (no collision).")

    @model_validator(mode="after")
    def _one_place(self) -> "Target":
        if (self.link is None) == (not self.surface_of):
            raise ValueError("give exactly one of 'link' (a fixed point) or 'surface_of' (a point drawn on limbs at every reset)")
        if self.surface_of and (self.offset_m != (0.0, 0.0, 0.0) or self.offset_by_variant):
            raise ValueError("@surface_of: a target drawn on a surface takes no offset_m or offset_by_variant")
        return self


class ClearedBy(Strict):
    """A marker is cleared when a contact between this tool link and the person lies within radius of it."""

    tool: Ref = Field(description="The tool link that clears markers, e.g. wiper.surface.")
    radius_m: float = Field(0.025, gt=0, le=0.5, description="Clearing radius around a contact point, metres.")


class Markers(Strict):
    """Points laid out in rings around person limbs (e.g. spots to wipe in bed bathing): rings every
    ``spacing_m`` along each capsule, points every ``spacing_m`` around each ring (the reference's
    capsule_points). Each is cleared once per episode."""

    surface_of: list[Ref] = Field(min_length=1, description="Person limbs (capsule links) to cover, e.g. person.right_shoulder.")
    spacing_m: float = Field(0.03, gt=0.005, le=0.5, description="Distance between rings and between points on a ring, metres.")
    cleared_by: ClearedBy = Field(description="What clears a marker.")
    show_rgba: Rgba | None = Field(None, description="Draw the markers not yet cleared as small spheres in renders.")


class ConsumedAt(Strict):
    """A particle is consumed (removed, counted) when it comes within radius of a target."""

    target: Ref = Field(description="The target that consumes particles, e.g. mouth.")
    radius_m: float = Field(gt=0, le=1, description="Consumption radius, metres.")
    outside_of: Ref | None = Field(
        None, description="A tool with a container (e.g. the cup): particles still inside it are not consumed or lost."
    )


class LostBeyond(Strict):
    """A particle is lost (removed, counted) when it is farther than distance from a body."""

    body: Ref = Field(description="The body the particle must stay near, e.g. the spoon.")
    distance_m: float = Field(gt=0, le=10, description="Distance beyond which it is lost, metres.")


class RestInContainer(Strict):
    """A simulation shortcut: particles resting in their container ride with it instead of being simulated.

    While the container's effective tilt — the angle between its axis (+z, towards the opening)
    and the apparent "up" −(g − a), with a the container's acceleration — stays below
    ``max_tilt_deg``, a heap of particles at rest in it does not flow, so the runtime carries them
    rigidly in the container's frame and takes them out of the physics (no contacts to solve).
    Once the tilt exceeds it they are put back where they were carried, with the container's
    velocity, and simulated again; they rest again once the tilt is below the limit, every active
    particle is inside the container and none moves faster than ``max_speed_mps`` relative to it.
    What this trades: sloshing under accelerations below the limit is not simulated.
    """

    container: Ref = Field(description="A tool with a container (e.g. the cup) that carries the resting particles.")
    max_tilt_deg: float = Field(
        20.0, gt=0, le=60, description="Effective tilt (degrees) above which resting particles are simulated again; keep it below the heap's angle of repose."
    )
    max_speed_mps: float = Field(
        0.02, gt=0, le=1, description="Speed relative to the container (m/s) below which simulated particles count as at rest."
    )


class Particles(Strict):
    """A grid of small spheres (food, water) with a lifecycle: active → consumed | lost."""

    grid: tuple[int, int, int] = Field(description="Particles along x, y, z of the attach frame.")
    radius_m: float = Field(gt=0, le=0.1, description="Sphere radius, metres.")
    mass_kg: float = Field(gt=0, le=10, description="Mass of one particle, kg.")
    spacing_m: float = Field(gt=0, le=1, description="Grid pitch, metres.")
    attach: Ref = Field(description="Body whose frame the grid is laid out in, e.g. the spoon.")
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Position of the first grid point in that frame, metres.")
    settle_steps: int = Field(0, ge=0, le=10_000, description="Physics steps run after placing them (compile time).")
    colors_rgba: list[Rgba] = Field(
        default_factory=lambda: [(0.8, 0.5, 0.2, 1.0)], min_length=1, description="Colours cycled over particles."
    )
    consumed_at: ConsumedAt | None = Field(None, description="When a particle is consumed.")
    lost_beyond: LostBeyond | None = Field(None, description="When a particle is lost (spilled).")
    hit_body: Ref | None = Field(
        None, description="Body whose first contact with an active particle counts as a hit (food on the person)."
    )
    rest: RestInContainer | None = Field(
        None, description="Carry particles at rest in a container with it instead of simulating them (a speed-up; see RestInContainer)."
    )

    @field_validator("grid")
    @classmethod
    def _positive(cls, v: tuple[int, int, int]) -> tuple[int, int, int]:
        if any(n < 1 for n in v):
            raise ValueError("every grid count must be ≥ 1")
        if v[0] * v[1] * v[2] > 2000:
            raise ValueError("at most 2000 particles")
        return v

    @property
    def count(self) -> int:
        return self.grid[0] * self.grid[1] * self.grid[2]


# --------------------------------------------------------------------------------------------
# Garments (cloth simulated as a stock-pybullet soft body)


class SleeveShape(Strict):
    """A generated sleeve: an open triangulated tube (see :mod:`assistive_compiler.garment`). Its
    frame: axis +z, the opening ring (where the hand enters) at z = 0 centred on the origin, the
    cuff at z = length_m. Node sets it exports: ``opening`` (ring 0), ``opening_top`` (ring 0
    within ±45° of +y) and ``cuff`` (the last ring)."""

    kind: Literal["sleeve"] = Field(description="Generated shape kind.")
    length_m: float = Field(gt=0.02, le=2.0, description="Tube length, metres.")
    radius_open_m: float = Field(gt=0.005, le=0.5, description="Radius of the opening ring, metres.")
    radius_end_m: float | None = Field(None, gt=0.005, le=0.5, description="Radius of the cuff ring, metres (None: the opening's).")
    rings: int = Field(8, ge=2, le=64, description="Rings of nodes along the tube (including both ends).")
    segments: int = Field(10, ge=3, le=64, description="Nodes around each ring.")


class SoftBodyPhysics(Strict):
    """Mass-spring settings of pybullet's deformable world (``loadSoftBody``). The defaults are the
    tested values of docs/dressing-study.md: stable with 4 solver sub-steps at a 0.02 s
    step for about 100 nodes (the springs are integrated explicitly: a stiffer, lighter or finer
    cloth needs more sub-steps)."""

    mass_kg: float = Field(0.1, gt=0, le=10, description="Total mass, kg (spread evenly over the nodes).")
    collision_margin_m: float = Field(0.01, gt=0, le=0.1, description="Collision margin of the cloth, metres.")
    elastic_stiffness: float = Field(10.0, gt=0, le=10_000, description="springElasticStiffness, N/m.")
    damping_stiffness: float = Field(
        0.002, ge=0, le=10, description="springDampingStiffness, N·s/m, damping all directions (≈ air drag per node; 0.1 freezes the cloth)."
    )
    bending_stiffness: float = Field(0.1, ge=0, le=10_000, description="springBendingStiffness, N/m.")
    friction: float = Field(0.5, ge=0, le=5, description="Friction coefficient of the cloth.")


class GarmentHold(Strict):
    """How the robot holds the garment: a node set pinned to the robot's hand (the pinned nodes
    follow the hand exactly; the rest of the cloth hangs and slides freely)."""

    hand: Literal["right", "left"] = Field(description="Which robot hand holds it (single-arm robots: their only hand).")
    grip: Name = Field(
        "garment",
        description="The robot part's grip (grips: in specs/robots/<robot>.yaml) giving the held frame in the hand's "
        "tool-mount frame; the robot's start pose (robot.start.tool_*) is this frame's pose.",
    )
    nodes: Name = Field("opening", description="Node set pinned to the held frame (e.g. opening: a hoop grip; opening_top: a pinch).")
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Garment frame origin in the held frame, metres.")
    rpy_deg: Vec3 = Field((0.0, 0.0, 0.0), description="Garment frame orientation in the held frame (roll, pitch, yaw), degrees.")


class GarmentSettle(Strict):
    """Compile-time settling: the garment hangs from the held frame (at the start orientation, away
    from everything) for ``steps`` physics steps under ``gravity_mps2``; the settled node positions
    are stored (held frame) and every reset starts from them (the reference settles 50 steps at g/2)."""

    steps: int = Field(50, ge=0, le=5000, description="Physics steps to settle.")
    gravity_mps2: float = Field(-4.905, ge=-20, le=0, description="Gravity while settling, m/s².")


class Garment(Strict):
    """A piece of clothing the robot holds, simulated as a pybullet soft body (stock pybullet: a
    deformable world, ``loadSoftBody``, ``createSoftBodyAnchor``). The compiler generates its mesh
    (OBJ) into the artifact. The garment's name is a body: ``<name>`` in contact terms (forces are
    scaled by the solver sub-steps, as pybullet reports a soft body's last sub-step only), the held
    frame as a point, and ``<name>.<node set>`` in terms that read cloth nodes."""

    shape: SleeveShape = Field(description="The generated shape.")
    physics: SoftBodyPhysics = Field(default_factory=SoftBodyPhysics, description="Soft-body settings.")
    held: GarmentHold = Field(description="How the robot holds it.")
    settle: GarmentSettle = Field(default_factory=GarmentSettle, description="Compile-time settling.")
    collides_with: list[Ref] | None = Field(
        None,
        description="Bodies the cloth collides with (e.g. [person]); None: every body and the floor. Soft-rigid contact "
        "is most of a cloth's cost, so leaving out bodies it should not touch (the robot that holds it, furniture) "
        "makes a step several times faster.",
    )
    rgba: Rgba = Field((0.543, 0.762, 0.289, 0.8), description="Colour in renders (the reference's gown green).")


# --------------------------------------------------------------------------------------------
# Terms: observations, rewards, preferences, success


class TermUse(Strict):
    """Use of a registered term: its kind, parameters (checked against the term's schema) and weight."""

    term: Name = Field(description="Registered term kind (see `assistive-compiler schema --terms`).")
    params: dict[str, Any] = Field(default_factory=dict, description="The term's parameters.")


class RewardTerm(TermUse):
    """One weighted reward term. The step reward is Σ weight·value; info reports every value."""

    name: Name = Field(description="Name of this term in info and logs.")
    weight: float = Field(description="Multiplier of the term's value (negative to penalise).")
    arms: Literal[1, 2] | None = Field(
        None, description="Only for robots acting with this many arms (2: a two-arm robot in a task with arm 'both'); "
        "None: every robot. E.g. the reference's single-arm arm manipulation doubles a distance term."
    )


class Observations(Strict):
    """Observation vectors per agent: features concatenated in order into one float32 Box."""

    robot: list[TermUse] = Field(min_length=1, description="The robot's observation features, in order.")
    human: list[TermUse] = Field(default_factory=list, description="The person's (co-optimisation) features.")


PREFERENCE_NAMES = (
    "velocity",
    "force_nontarget",
    "high_force",
    "food_hit",
    "food_velocity",
    "dressing_force",
    "pressure",
)
"""The paper's seven preference costs C_v, C_f, C_hf, C_fd, C_fdv, C_d, C_p, in its order."""

PAPER_PREFERENCE_WEIGHTS = dict(zip(PREFERENCE_NAMES, (0.25, 0.01, 0.05, 1.0, 1.0, 0.01, 0.01)))


class Preference(Strict):
    """One active preference cost: its inputs and, optionally, a weight other than the paper's."""

    weight: float | None = Field(None, ge=0, description="ω for this cost (None: the paper's value).")
    params: dict[str, Any] = Field(default_factory=dict, description="The cost's inputs (which link, which forces).")


class Preferences(Strict):
    """The human-preference reward r_H = Σ ω_k·c_k over the costs active for this task (α_k = 1)."""

    active: dict[Name, Preference] = Field(
        default_factory=dict, description=f"Active costs by name; names are {', '.join(PREFERENCE_NAMES)}."
    )


class Success(Strict):
    """Task success: an aggregate of one reward term's value over the episode against a threshold."""

    term: Name = Field(description="Name of a reward term whose value is aggregated.")
    aggregate: Literal["sum", "max", "min", "last"] = Field(description="How the per-step values are combined.")
    threshold: float = Field(description="Success when aggregate ≥ threshold.")
    relative_to: Name | None = Field(
        None, description="A particle or marker set: the threshold is then a fraction (0, 1] of its count."
    )

    @model_validator(mode="after")
    def _fraction(self) -> "Success":
        if self.relative_to is not None and not (0 < self.threshold <= 1):
            raise ValueError(f"@threshold: threshold {self.threshold:g} is a fraction of '{self.relative_to}' and must lie in (0, 1]")
        return self


# --------------------------------------------------------------------------------------------
# Scripted baseline


class Waypoint(Strict):
    """A goal for the scripted controller: a point near a target, reached within a tolerance."""

    to: Ref = Field(description="Target or link the goal is relative to, e.g. mouth.")
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Goal offset from that point, world frame, metres.")
    tolerance_m: float = Field(0.02, ge=0, le=1, description="Distance at which the next waypoint starts, metres.")
    normal_offset_m: float = Field(
        0.0, ge=-0.5, le=0.5, description="Offset along the target's outward surface normal (targets drawn on a surface), metres."
    )
    axis_offset_m: float = Field(
        0.0, ge=-0.5, le=0.5, description="Offset along the limb's axis, away from its joint (targets drawn on a surface), metres."
    )
    rpy_deg: Vec3 | None = Field(
        None, description="Orientation of the moved point's link at this waypoint (roll, pitch, yaw; world, degrees), e.g. "
        "to tilt a cup; None keeps the tool's start orientation."
    )
    face_normal_within_deg: float | None = Field(
        None, ge=0, le=180, description="Turn the tool, by the smallest rotation from its start orientation, until its "
        "pointing axis (from the end effector to the moved point) lies within this angle of the target's inward surface "
        "normal (targets drawn on a surface), so the tool meets the surface tip first instead of lying across the limb; "
        "degrees. None keeps the start orientation (or rpy_deg's)."
    )
    step_m: float | None = Field(
        None, gt=0, le=0.5, description="Largest distance, metres, between the moved point and the goal handed to IK while heading "
        "for this waypoint: the point then follows the straight line from where it is (e.g. wiping along a limb) instead of the "
        "joint-space path one IK jump takes. None: IK aims at the waypoint itself."
    )


class _WaypointScript(Strict):
    """A list of waypoints with an optional repeat_from (ScriptedArm, ScriptedRobot, Scripted)."""

    @model_validator(mode="after")
    def _repeat_in_range(self) -> "_WaypointScript":
        if self.repeat_from is not None and self.repeat_from >= len(self.waypoints):  # type: ignore[attr-defined]
            raise ValueError(f"@repeat_from: repeat_from {self.repeat_from} is not a waypoint index (0..{len(self.waypoints) - 1})")  # type: ignore[attr-defined]
        return self


class ScriptedArm(_WaypointScript):
    """The left arm's part of a scripted baseline when the robot acts with both arms."""

    move: Ref = Field(description="The point the left arm moves, e.g. scooper_left.blade.")
    waypoints: list[Waypoint] = Field(min_length=1, description="Goals in order; the last is held unless repeat_from is given.")
    repeat_from: int | None = Field(None, ge=0, description="After the last waypoint, go on from this index; None holds the last.")



class ScriptedRobot(_WaypointScript):
    """One robot's own script: its waypoints replace the task's for that robot (robots differ in
    reach and in the wrist orientations they can hold, so one set of waypoints rarely suits all)."""

    move: Ref | None = Field(None, description="The point moved; None: the task's scripted.move.")
    waypoints: list[Waypoint] = Field(min_length=1, description="Goals in order, replacing scripted.waypoints for this robot; the last is held unless repeat_from is given.")
    repeat_from: int | None = Field(None, ge=0, description="After the last waypoint, go on from this index (replacing scripted.repeat_from); None holds the last.")



class Scripted(_WaypointScript):
    """A privileged baseline controller (IK each step) that moves a point of the tool through
    waypoints, keeping the tool's start orientation. It shows the task is solvable and checks the
    reward wiring; it is not a learned policy."""

    move: Ref = Field(description="The point moved, e.g. spoon (its reference link) or spoon.tip.")
    waypoints: list[Waypoint] = Field(min_length=1, description="Goals in order; the last is held unless repeat_from is given.")
    repeat_from: int | None = Field(
        None, ge=0, description="After the last waypoint, go on from this index (e.g. to rub back and forth); None holds the last."
    )
    left: ScriptedArm | None = Field(
        None, description="The left arm's waypoints when the robot acts with both arms (robot.arm: both, a two-arm robot); "
        "move/waypoints then drive the right arm. Ignored on one-arm robots."
    )
    right: ScriptedArm | None = Field(
        None, description="The right arm's part when the robot acts with both arms (robot.arm: both, a two-arm robot): it "
        "replaces move/waypoints/repeat_from there, so that a two-arm script (e.g. lift with both hands) can differ from the "
        "one-arm script that move/waypoints give. Ignored on one-arm robots."
    )
    per_robot: dict[Name, ScriptedRobot] = Field(
        default_factory=dict, description="Scripts by robot name: the named robot follows its own move/waypoints/repeat_from "
        "instead of the ones above (left/right still apply to two-arm robots acting with both arms)."
    )


# --------------------------------------------------------------------------------------------
# The task


class CameraView(Strict):
    """Where renders look from (world frame: the person faces −Y; the robot usually stands at −X)."""

    eye_m: Vec3 | None = Field(None, description="Camera position, world frame, m (default: the shipped default view's).")
    target_m: Vec3 | None = Field(None, description="Point the camera looks at, world frame, m.")
    fov_deg: float | None = Field(None, gt=5, lt=150, description="Vertical field of view, degrees.")


class Camera(CameraView):
    """The task's camera for renders, with per-robot overrides (each field merged over the task's)."""

    per_robot: dict[Name, CameraView] = Field(
        default_factory=dict, description="Per-robot camera fields (e.g. a robot standing farther away needs a wider view).")


class TaskSpec(Strict):
    """A complete assistive task."""

    name: Name = Field(description="Task name; Gymnasium ids are <TaskName><Robot>-v1.")
    title: str = Field(description="Human-readable title, e.g. 'Feeding'.")
    description: str = Field("", description="What the task is and where its numbers come from.")
    extends: str | None = Field(
        None, description="Path of a spec this one builds on (relative to this file, or shipped:tasks/<name>.yaml for a "
        "shipped one). Mappings merge key by key and anything else is replaced; inside a mapping, '$delete: [key, ...]' "
        "removes inherited keys and '$replace: VALUE' (alone) takes VALUE instead of merging.",
    )
    sim: Sim = Field(default_factory=Sim, description="Timing and world physics.")
    scene: Scene = Field(default_factory=Scene, description="Furniture and objects.")
    person: Person = Field(description="The person being helped.")
    robot: RobotRole = Field(description="The robot's role.")
    tools: dict[Name, ToolUse] = Field(default_factory=dict, description="Tools by name.")
    targets: dict[Name, Target] = Field(default_factory=dict, description="Named points on bodies.")
    particles: dict[Name, Particles] = Field(default_factory=dict, description="Particle sets by name.")
    markers: dict[Name, Markers] = Field(default_factory=dict, description="Marker sets on the person by name (e.g. spots to wipe).")
    garments: dict[Name, Garment] = Field(
        default_factory=dict, max_length=1, description="Garments by name (soft bodies held by the robot, e.g. a gown sleeve); at most one."
    )
    observations: Observations = Field(description="Observation features per agent.")
    reward: list[RewardTerm] = Field(min_length=1, description="Weighted reward terms.")
    preferences: Preferences = Field(default_factory=Preferences, description="Human-preference costs.")
    success: Success = Field(description="What counts as success.")
    scripted: Scripted | None = Field(None, description="A scripted baseline controller (optional).")
    camera: Camera = Field(default_factory=Camera, description="The camera of renders (render, demo): eye, target, field of view; per robot.")

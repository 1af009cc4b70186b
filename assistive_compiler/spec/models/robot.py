"""``robot`` and ``tools``: the robot's role (arm, mounting, control, start pose of the tool, base
search, per-robot overrides) and the tools it holds."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from .common import Name, Ref, Strict, Vec3


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
        None,
        description="Which arm reaches it when the robot acts with both arms (robot.arm: both); None: the right "
        "(acting) arm. A one-arm robot reaches every goal with its arm.",
    )


class BaseSearch(Strict):
    """Compile-time base-pose optimisation for robots standing on the floor (paper §III-D): sample base
    poses, solve IK to each goal with collision checks, keep the poses that reach the most goals,
    ties broken by joint-limit-weighted kinematic isotropy (JLWKI). The start pose is always a
    required, oriented goal. Deterministic and bounded: exactly ``attempts`` samples."""

    origin_m: Vec3 = Field(
        (-0.85, -0.4, 0.0), description="Anchor of the sampling box in the world (x, y), m; z is ignored."
    )
    x_range_m: tuple[float, float] = Field((-0.5, 0.0), description="Uniform x offset from the anchor, m.")
    y_range_m: tuple[float, float] = Field((-0.5, 0.5), description="Uniform y offset from the anchor, m.")
    yaw_deg: float = Field(0.0, ge=-360, le=360, description="Base yaw before noise, degrees.")
    yaw_noise_deg: float = Field(30.0, ge=0, le=180, description="Half-width of the uniform yaw noise, degrees.")
    attempts: int = Field(100, ge=1, le=5000, description="Base poses sampled (the paper: 100).")
    keep: int = Field(4, ge=1, le=32, description="Best base poses stored in the artifact; reset() picks among them.")
    goals: list[Goal] = Field(default_factory=list, description="Goals scored besides the start pose.")


class PerRobot(Strict):
    """Task settings that differ per robot (the reference's per-task robot tables)."""

    base_offset_m: Vec3 | None = Field(
        None,
        description="Base position offset from the mount or the search anchor, m (the reference's toc_base_pos_offset).",
    )
    start: StartGoal | None = Field(
        None,
        description="This robot's start pose, replacing robot.start (e.g. a one-arm robot's single start in a two-arm task).",
    )
    base_search: BaseSearch | None = Field(
        None,
        description="This robot's base search, replacing robot.base_search (e.g. a robot that reaches a goal only "
        "part of the time, where the task requires it of the others).",
    )
    arm_rest_rad: list[float] | None = Field(
        None,
        description="The acting arm's configuration (rad or m, in the arm's joint order) that the compile-time IK "
        "(base search, start states) starts from, replacing the robot part's rest_rad in this task (e.g. Panda's default "
        "all-zero rest, a straight-up arm on joint 4's limit, led its bed-bathing starts into configurations at the limits).",
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
        None,
        description="Start pose of the left arm's tool when arm is 'both' and the robot has two arms (one-arm robots "
        "use start, or per_robot.<robot>.start).",
    )
    base_search: BaseSearch = Field(
        default_factory=BaseSearch, description="Base placement of robots that are not mounted."
    )
    per_robot: dict[Name, PerRobot] = Field(default_factory=dict, description="Per-robot settings by robot name.")

    def search_for(self, robot: str) -> BaseSearch:
        """The base search ``robot`` uses: its per_robot one if it has one, else the task's."""
        own = self.per_robot.get(robot)
        return own.base_search if own is not None and own.base_search is not None else self.base_search

    def arm_rest_for(self, robot: str) -> list[float] | None:
        """The acting arm's rest pose (rad) where ``robot``'s IK begins in this task: its
        per_robot ``arm_rest_rad``, or None (the robot part's own ``rest_rad``)."""
        own = self.per_robot.get(robot)
        return own.arm_rest_rad if own is not None else None

    @model_validator(mode="after")
    def _default_supported(self) -> RobotRole:
        if self.default not in self.supported:
            from ...errors import did_you_mean

            raise ValueError(
                f"@default: default robot '{self.default}' is not in supported {self.supported}{did_you_mean(self.default, self.supported)}"
            )
        if self.start_left is not None and self.arm != "both":
            raise ValueError(
                f"@start_left: start_left is the left arm's start in a task acting with both arms, but this task's arm is '{self.arm}'; remove it or set arm: both"
            )
        return self


class ToolUse(Strict):
    """A tool the robot holds, rigidly attached to the robot's tool-mount link."""

    part: Name = Field(description="Tool part from the library (specs/tools/<part>.yaml).")
    hand: Literal["right", "left"] = Field(description="Which hand holds it (single-arm robots: their only hand).")
    gravity_mps2: float | None = Field(0.0, ge=-20, le=0, description="Gravity on the tool (0: weightless).")
    mass_kg: float | None = Field(None, gt=0, description="Mass override in kg (None: the part's mass).")
    grip: Name | None = Field(
        None,
        description="Which of the robot part's grips (grips: in specs/robots/<robot>.yaml) holds this tool; default "
        "the robot's grip named like the tool part, else the tool part's own grip for the robot (grips: <robot>: in "
        "specs/tools/<part>.yaml: how a tool in your library is held by a shipped robot). A new tool shaped like a "
        "shipped one can reuse its grip (e.g. grip: scratcher).",
    )
    friction: float | None = Field(
        None,
        ge=0,
        le=5,
        description="Lateral friction coefficient of every link of the tool in this task (None: the tool part's "
        "friction, else pybullet's default 0.5). A tool whose friction is set stays a free body, never welded.",
    )
    one_arm_same_as: Name | None = Field(
        None,
        description="On a robot acting with one arm (which serves as both hands), this tool is the named tool, held "
        "in the other hand: one body that both names refer to (the reference's single-arm arm manipulation, paper §III-B). "
        "Two-arm robots acting with both arms hold both tools.",
    )

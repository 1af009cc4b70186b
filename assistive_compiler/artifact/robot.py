"""The robot as compiled: its action joints and scaling, named links, base placement and drive,
precomputed starts, and the tools it holds (world frame, m; rad)."""

from __future__ import annotations

from pydantic import Field

from .model import ArtifactModel, Quat, Vec3


class StartState(ArtifactModel):
    """One precomputed start: a robot base pose and the arm configuration that puts the tool at a
    (noisy) start pose from it, collision-free."""

    base_position: Vec3 = Field(description="Robot base frame position, world, m.")
    base_orientation: Quat = Field(description="Robot base frame orientation, world.")
    joints: list[float] = Field(description="Arm joint angles in action order, rad.")
    tool_position: Vec3 = Field(description="Where the tool frame (or end effector) starts, world, m.")


class Drive(ArtifactModel):
    """A differential-drive base on a planar chain (see :class:`assistive_compiler.spec.parts.BaseDrive`)."""

    joints: tuple[str, str, str] = Field(description="The x, y (prismatic, m) and yaw (revolute, rad) joints.")
    base_link: str = Field(description="The moving base link (robot_base observations are in its frame).")
    wheel_radius: float = Field(description="Wheel radius, m.")
    wheel_separation: float = Field(description="Distance between the wheels, m.")
    action_scale: float = Field(description="Wheel turn per unit action per physics step, rad.")
    position_gain: float = Field(description="Position gain of the drive joints.")
    max_force: tuple[float, float, float] = Field(description="Force limits of x, y (N) and yaw (N·m).")


class BasePose(ArtifactModel):
    """A robot base pose the compile-time search kept (world frame)."""

    position: Vec3 = Field(description="Base position, world frame, m.")
    yaw_rad: float = Field(description="Base yaw about +z, rad.")
    goals_reached: int = Field(description="Reach goals the arm reaches from it without collision.")
    goals: int = Field(description="Reach goals searched for.")
    jlwki: float = Field(
        description="Joint-limit-weighted kinematic isotropy summed over the reached goals (higher: more dexterous)."
    )


class BaseSearch(ArtifactModel):
    """The base was placed by the compile-time search (paper §IV): the poses it kept, best first."""

    base_poses: list[BasePose] = Field(description="Kept base poses, best first; reset() draws starts among them.")


class Mounted(ArtifactModel):
    """The base is mounted on a furniture piece (no search)."""

    mounted_on: str = Field(description="The furniture the robot is mounted on.")


class Robot(ArtifactModel):
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

    @property
    def action_size(self) -> int:
        """Length of the robot's action: two wheel dimensions with a drive, then one per arm joint."""
        return len(self.arm_joints) + (2 if self.drive is not None else 0)


class ToolAttachment(ArtifactModel):
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

"""Library parts: robots, tools, furniture and people, each a small YAML file under ``specs/``.

A part names its xacro template, the template's parameters, and the *semantic* names specs use
(``end_effector``, ``tip``, ``seat``) mapped to the URDF's real link and joint names. Semantic names
are checked against the rendered URDF when the part is loaded, so a spec that validates refers
only to links that exist.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from .models import Name, Strict, Vec3

TemplateParam = float | int | str | bool


class Template(Strict):
    """A xacro template and the parameters it is rendered with."""

    path: str = Field(description="Template path relative to the templates/ directory.")
    params: dict[str, TemplateParam] = Field(default_factory=dict, description="xacro args (strings after rendering).")


class Arm(Strict):
    """One arm of a robot."""

    joints: list[str] = Field(min_length=1, description="Arm joints from base to wrist (URDF names), in action order.")
    end_effector: str = Field(description="URDF link whose pose is the end effector.")
    tool_mount: str = Field(description="URDF link tools are attached to.")
    rest_rad: list[float] | None = Field(None, description="Rest (tucked) configuration, radians; default zeros.")
    follow: dict[str, str] = Field(
        default_factory=dict,
        description="Joints (URDF names) moved with one of this arm's joints: follower -> leader. A follower gets its leader's "
        "target change every step and its value at start (the reference's action duplication: Stretch's four telescoping "
        "tubes, one action). Followers are not in the action or in joint-angle observations.",
    )
    action_multipliers: list[float] | None = Field(
        None,
        description="Per arm joint, a factor on the task's action scale (the reference's per-robot action multipliers, "
        "e.g. Stretch's lift 2, telescoping 1, wrist 2); default 1 for every joint.",
    )

    @model_validator(mode="after")
    def _followers_and_multipliers(self) -> Arm:
        for follower, leader in self.follow.items():
            if leader not in self.joints:
                raise ValueError(
                    f"@follow: follower '{follower}' follows '{leader}', which is not one of this arm's joints {self.joints}"
                )
            if follower in self.joints:
                raise ValueError(
                    f"@follow: '{follower}' is one of the arm's joints; a follower is a joint moved with them, not one of them"
                )
        if self.action_multipliers is not None and len(self.action_multipliers) != len(self.joints):
            raise ValueError(
                f"@action_multipliers: {len(self.action_multipliers)} multipliers for {len(self.joints)} arm joints; give one per joint"
            )
        return self


class Gripper(Strict):
    """Gripper joints; their position is set per held tool."""

    joints: list[str] = Field(default_factory=list, description="Finger joints (URDF names).")
    positions: dict[Name, float | list[float]] = Field(
        default_factory=dict,
        description="Finger position per tool part held ('none' = no tool), radians or metres: one value for "
        "every finger joint, or one per joint in the order of joints (fingers that open in opposite directions).",
    )


class ToolGrip(Strict):
    """How a robot holds a tool part: the tool frame relative to the tool-mount link frame."""

    position_m: Vec3 = Field((0.0, 0.0, 0.0), description="Tool frame origin in the tool-mount frame, metres.")
    rpy_rad: Vec3 = Field((0.0, 0.0, 0.0), description="Tool frame orientation in the tool-mount frame, radians.")


class BaseDrive(Strict):
    """A mobile base driven by two wheel actions (a differential drive), modelled as a planar chain:
    prismatic x, prismatic y and revolute yaw joints between the placed root frame and the base.
    The first two action dimensions are the right and left wheel's turn (rad per unit action per
    physics step: the task's action scale times ``action_multiplier``); each step the runtime moves
    the three joints' targets as the wheels rolling without slip would: forward
    ``r (Δθ_r + Δθ_l) / 2`` along the current heading and turning by ``r (Δθ_r − Δθ_l) / separation``."""

    joints: tuple[str, str, str] = Field(
        description="The planar chain's joints (URDF names): x, y (prismatic, m) and yaw (revolute, rad)."
    )
    base_link: str = Field(
        description="The link the chain carries (the moving base): the frame of robot_base observations."
    )
    wheel_radius_m: float = Field(gt=0, le=1, description="Wheel radius, m.")
    wheel_separation_m: float = Field(gt=0, le=5, description="Distance between the two wheels' contact points, m.")
    action_multiplier: float = Field(1.0, gt=0, description="Factor on the task's action scale for the wheel actions.")
    position_gain: float = Field(gt=0, le=1, description="Position gain of the three drive joints.")
    max_force_n: float = Field(
        gt=0, description="Force limit of the x and y joints, N (what the wheel motors can push)."
    )
    max_torque_nm: float = Field(gt=0, description="Torque limit of the yaw joint, N·m.")


class RobotControlDefaults(Strict):
    """The robot's own control defaults; a task's ``robot.control`` values, where it sets them, win."""

    position_gain: float | None = Field(None, gt=0, le=1, description="Arm position gain.")
    max_force_nm: float | None = Field(None, gt=0, description="Arm motor force limit, N·m.")


class RobotPart(Strict):
    """A robot in the library."""

    name: Name = Field(description="Robot name used on the command line and in Gymnasium ids.")
    title: str = Field(description="Display name, e.g. 'Jaco' (used in ids: FeedingJaco-v1).")
    template: Template | None = Field(None, description="Our xacro template (or give urdf).")
    urdf: str | None = Field(
        None,
        description="A URDF instead of a template (bring your own robot): a path relative to this file, "
        "or 'python-package:<package>/<path>' for one shipped inside an installed package (e.g. pybullet_data).",
    )
    base_link: str = Field(description="URDF root link.")
    arms: dict[Literal["right", "left"], Arm] = Field(
        min_length=1, description="Arms by side; a single-arm robot lists one and uses it for either side."
    )
    gripper: dict[Literal["right", "left"], Gripper] = Field(default_factory=dict, description="Grippers by side.")
    grips: dict[Name, ToolGrip] = Field(default_factory=dict, description="Tool attachment per tool part.")
    mountable: bool = Field(
        False, description="Mounted on furniture (e.g. Jaco on a wheelchair) when a task offers it."
    )
    control: RobotControlDefaults = Field(
        default_factory=RobotControlDefaults, description="Control defaults for tasks that do not set them."
    )
    base_height_m: float = Field(0.0, ge=0, description="Height of the base link above the floor when on the floor.")
    base_drive: BaseDrive | None = Field(
        None, description="A mobile base driven by wheel actions (None: the base stays where it is placed)."
    )
    facing_yaw_deg: float = Field(
        0.0,
        ge=-180,
        le=180,
        description="Base yaw (degrees) at which the robot works towards world +x (added to base_search.yaw_deg): 0 "
        "for arms reaching along their base's +x; 90 for Stretch, whose arm extends along its base's -y.",
    )

    @model_validator(mode="after")
    def _one_source(self) -> RobotPart:
        if (self.template is None) == (self.urdf is None):
            raise ValueError("give exactly one of 'template' or 'urdf'")
        return self

    def arm_for(self, side: str) -> tuple[str, Arm]:
        """The arm acting as ``side``: itself, or the only arm of a single-arm robot."""
        if side in self.arms:
            return side, self.arms[side]  # type: ignore[index]
        ((only_side, only_arm),) = self.arms.items()
        return only_side, only_arm


class Container(Strict):
    """A tool's inside: a vertical cylinder in the tool frame from z = 0 (the inside floor) up to
    ``height_m``, opening towards +z. Particles within it count as still held."""

    radius_m: float = Field(gt=0, le=1, description="Inner radius, metres.")
    height_m: float = Field(gt=0, le=2, description="Height of the rim above the inside floor, metres.")


class ToolPart(Strict):
    """A hand-held tool."""

    name: Name = Field(description="Tool part name.")
    template: Template = Field(description="The tool's xacro template.")
    base_link: str = Field(description="URDF root link; its frame is the tool frame the robot grip refers to.")
    links: dict[Name, str] = Field(default_factory=dict, description="Semantic link names → URDF link names.")
    reference_link: Name = Field(description="Semantic link meant when a spec names the tool alone (e.g. tip).")
    mass_kg: float = Field(gt=0, description="Total mass, kg.")
    container: Container | None = Field(None, description="The open volume the tool holds things in (a cup), if any.")
    grips: dict[Name, ToolGrip] = Field(
        default_factory=dict,
        description="How each robot holds this tool, by robot name (the tool frame in the robot's tool-mount frame): "
        "a tool in your own library brings its grips for the robots it is used with, shipped ones included. A robot "
        "part's own grip of this tool's name (grips: in the robot's file) is used where it has one; giving both is "
        "an error.",
    )
    friction: float | None = Field(
        None,
        ge=0,
        le=5,
        description="Lateral (Coulomb) friction coefficient of every link of the tool, set in pybullet when it is "
        "loaded (None: pybullet's default, 0.5). A tool whose friction is set stays a free body held at its grip, "
        "never welded into the robot. A task's tools.<name>.friction overrides it.",
    )


class FurniturePart(Strict):
    """Furniture or a free object."""

    name: Name = Field(description="Furniture part name.")
    template: Template = Field(description="The xacro template.")
    base_link: str = Field(description="URDF root link.")
    static: bool = Field(True, description="Fixed in the world by default.")
    friction: float = Field(1.0, ge=0, description="Lateral friction.")
    links: dict[Name, str] = Field(default_factory=dict, description="Semantic link names → URDF link names.")
    seat_link: str | None = Field(None, description="URDF link whose frame is the seat surface (for seated people).")
    mount_link: str | None = Field(None, description="URDF link whose frame is where a mounted robot's base goes.")
    mount_params: dict[str, str] = Field(
        default_factory=dict, description="Template params to set when a robot is mounted (e.g. robot_mount: right)."
    )


class PersonPart(Strict):
    """A person's body: sex and size. Posture, impairments and control belong to the task."""

    name: Name = Field(description="Person part name, e.g. male_50th.")
    sex: Literal["male", "female"] = Field(description="Body model (the reference's male or female segment tables).")
    mass_kg: float | None = Field(
        None,
        gt=20,
        le=250,
        description="Total body mass, kg (paper: 78.4 male, 62.5 female); required unless percentile is given.",
    )
    percentile: float | None = Field(
        None,
        description="Body percentile, 5-95 (e.g. 5, 50, 95): standing height and mass follow from the CDC/NCHS adult "
        "stature and weight percentiles (2021-2023), scaled so that 50 is the paper's body; instead of mass_kg, height_m "
        "and height_scale.",
    )
    height_m: float | None = Field(
        None,
        gt=1.0,
        le=2.3,
        description="Standing height, metres (the segment-length scale is solved for); or give height_scale.",
    )
    height_scale: float = Field(1.0, gt=0.5, le=1.5, description="Multiplier of segment lengths (1.0: 50th pct).")
    radius_scale: float = Field(1.0, gt=0.5, le=2.0, description="Multiplier of segment radii.")
    skin_rgba: tuple[float, float, float, float] = Field((0.8, 0.6, 0.4, 1.0), description="Skin colour.")

    @model_validator(mode="after")
    def _one_height(self) -> PersonPart:
        if self.height_m is not None and self.height_scale != 1.0:
            raise ValueError("@height_m: give height_m or height_scale, not both")
        return self

    @model_validator(mode="after")
    def _size(self) -> PersonPart:
        if self.percentile is None:
            if self.mass_kg is None:
                raise ValueError("@mass_kg: give mass_kg (kg) or percentile")
            return self
        from ..person.anthropometry import check_percentile

        if self.mass_kg is not None:
            raise ValueError("@percentile: give percentile or mass_kg, not both (the percentile sets the mass)")
        if self.height_m is not None or "height_scale" in self.model_fields_set:
            which = "height_m" if self.height_m is not None else "height_scale"
            raise ValueError(f"@percentile: give percentile or {which}, not both (the percentile sets the height)")
        try:
            check_percentile(self.percentile)
        except ValueError as exc:
            raise ValueError(f"@percentile: {str(exc).removeprefix('percentile ')}") from None
        return self

    def size(self) -> tuple[float | None, float]:
        """``(standing height m or None, mass kg)`` as given or as the percentile sets them (None:
        the height follows from height_scale)."""
        if self.percentile is not None:
            from ..person.anthropometry import percentile_body

            return percentile_body(self.sex, self.percentile)
        return self.height_m, self.mass_kg

    def measurements(self):
        """The body model of this person (segment lengths, radii and masses). A percentile body is
        solved for its standing height like height_m, with its radii scaled by the girth factor
        √((m/m₅₀)/(h/h₅₀)) so its volume follows its mass (a heavier body at the same height is
        wider, not denser); the 50th percentile is the paper's body itself (both scales 1)."""
        from ..person.anthropometry import percentile_body
        from ..person.body import body_for_height, body_measurements

        if self.percentile is not None:
            height, mass = self.size()
            if self.percentile == 50:
                return body_measurements(self.sex, mass, 1.0, self.radius_scale)
            height_50, mass_50 = percentile_body(self.sex, 50)
            girth = ((mass / mass_50) / (height / height_50)) ** 0.5
            return body_for_height(self.sex, height, mass, self.radius_scale * girth)
        if self.height_m is not None:
            return body_for_height(self.sex, self.height_m, self.mass_kg, self.radius_scale)
        return body_measurements(self.sex, self.mass_kg, self.height_scale, self.radius_scale)


def tool_grip(robot: RobotPart, tool: ToolPart, grip: str | None = None) -> ToolGrip | None:
    """How ``robot`` holds ``tool``: the robot's grip named ``grip`` when the task names one, else
    the robot's grip named like the tool part, else the tool part's grip for this robot (None:
    no grip; giving both the robot's and the tool's is a resolve error)."""
    if grip is not None:
        return robot.grips.get(grip)
    return robot.grips.get(tool.name, tool.grips.get(robot.name))

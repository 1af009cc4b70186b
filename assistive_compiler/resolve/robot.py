"""The ``robot`` section: which robot, which of its arms act, how it is mounted, its goals.

Checks that the robot is one the task supports and the library has, that ``per_robot`` keys name
known robots, that each tool's hand is one the robot acts with (``one_arm_same_as`` aliases on a
one-arm robot), that the mount furniture exists and fits ``mount_base``, that the robot has a grip
for every tool, and the base-search goals. Produces the acting sides, the tool aliases, the
robot's semantic links, the joint groups (robot arms and person groups) and the base goals.
"""

from __future__ import annotations

from collections.abc import Iterable

from ..errors import did_you_mean, one_of
from ..library import LoadedPart, is_shipped
from ..references import JointGroup
from ..spec.models import TaskSpec
from .located import expected
from .resolved import BaseGoal
from .scope import Scope


def check_supported(s: Scope) -> None:
    """Every supported robot is in the library; the robot asked for is supported (else raise at once)."""
    spec = s.spec
    for i, name in enumerate(spec.robot.supported):
        if not s.lib.path_of("robots", name):
            s.problem(
                ("robot", "supported", i),
                f"unknown robot '{name}'; {expected(s.lib.names('robots'), name)}{s.lib.searched('robots')}",
            )
    if s.robot_name not in spec.robot.supported:
        # Located at the list that decides (robot.supported), wherever it was written.
        s.problem(
            ("robot", "supported"),
            f"robot '{s.robot_name}' is not supported by task '{spec.name}'; supported: "
            f"{one_of(spec.robot.supported)}{did_you_mean(s.robot_name, spec.robot.supported)}",
        )
        s.fail_if_any()


def check_per_robot_keys(s: Scope, path: tuple, names: Iterable[str]) -> None:
    """``per_robot`` keys name known robots (not only supported ones: a spec extending this one
    may support more)."""
    known = s.lib.names("robots")
    for name in names:
        if name not in known:
            s.problem(path + (name,), f"per_robot names unknown robot '{name}'; {expected(known, name)}", key=True)


def acting_sides(spec: TaskSpec, robot: LoadedPart) -> tuple[str, ...]:
    """The acting sides in action order (see ResolvedTask.sides)."""
    if spec.robot.arm == "both" and len(robot.part.arms) > 1:
        return ("right", "left")
    return (spec.robot.arm if spec.robot.arm != "both" else "right",)


def tool_aliases(s: Scope) -> dict[str, str]:
    """Which tools share another tool's body on this robot, checking that every tool's hand is
    one the robot acts with: on a robot acting with one arm, a tool in the other hand must be
    ``one_arm_same_as`` a tool of the same part in the acting hand (paper §III-B)."""
    spec = s.spec
    aliases: dict[str, str] = {}
    one_arm = len(s.sides) == 1
    robot_arms = len(s.robot.part.arms)
    for name, use in spec.tools.items():
        path = ("tools", name)
        other = use.one_arm_same_as
        if other is not None:
            if other not in spec.tools or other == name:
                pool = [t for t in spec.tools if t != name]
                s.problem(path + ("one_arm_same_as",), f"unknown tool '{other}'; {expected(pool, other, empty='none')}")
                continue
            target = spec.tools[other]
            if target.one_arm_same_as is not None:
                s.problem(
                    path + ("one_arm_same_as",),
                    f"tool '{other}' is itself one_arm_same_as '{target.one_arm_same_as}'; name a tool that is a body of its own",
                )
            elif target.part != use.part:
                s.problem(
                    path + ("one_arm_same_as",),
                    f"tool '{other}' is a '{target.part}' but '{name}' is a '{use.part}'; one body can only stand for tools of the same part",
                )
            elif target.hand == use.hand:
                s.problem(
                    path + ("one_arm_same_as",),
                    f"tool '{other}' is already in the {use.hand} hand; one_arm_same_as names the tool in the other hand",
                )
            elif one_arm:
                aliases[name] = other
                continue
        if one_arm and spec.robot.arm != "both" and robot_arms > 1 and use.hand != spec.robot.arm:
            s.problem(
                path + ("hand",),
                f"tool '{name}' is held in the {use.hand} hand, but the task acts with the {spec.robot.arm} arm only; use hand: {spec.robot.arm} or robot.arm: both",
            )
    if one_arm:
        held = [n for n in spec.tools if n not in aliases]
        hands = {spec.tools[n].hand for n in held}
        if len(hands) > 1 and (robot_arms == 1 or spec.robot.arm == "both"):
            first = held[0]
            for n in held[1:]:
                if spec.tools[n].hand != spec.tools[first].hand:
                    s.problem(
                        ("tools", n, "hand"),
                        f"robot '{s.robot_name}' acts with one arm, which would hold both '{first}' ({spec.tools[first].hand} hand) and '{n}' ({spec.tools[n].hand} hand); give '{n}' one_arm_same_as: {first} (one tool serving both hands) or a hand the arm already uses",
                    )
    return aliases


def robot_links(s: Scope) -> dict[str, str]:
    """The robot's semantic link names (``base``, ``end_effector``, ``<side>_tool_mount``, ...) -> URDF links."""
    part = s.robot.part
    side = s.spec.robot.arm if s.spec.robot.arm != "both" else "right"
    out = {"base": part.base_link}
    _, arm = part.arm_for(side)
    out["end_effector"], out["tool_mount"] = arm.end_effector, arm.tool_mount
    for side in ("right", "left"):
        _, a = part.arm_for(side)
        out[f"{side}_end_effector"], out[f"{side}_tool_mount"] = a.end_effector, a.tool_mount
    return out


def joint_groups(s: Scope) -> dict[str, JointGroup]:
    """``robot.arm`` (the acting arms' joints), ``robot.<side>_arm`` and every ``person.<group>``."""
    from ..person.skeleton import JOINT_GROUPS

    part = s.robot.part
    groups: dict[str, JointGroup] = {}
    arm_joints: list[str] = []
    for side in acting_sides(s.spec, s.robot):
        arm_joints += part.arm_for(side)[1].joints
    groups["robot.arm"] = JointGroup(body="robot", group="arm", joints=tuple(arm_joints))
    for side in ("right", "left"):
        groups[f"robot.{side}_arm"] = JointGroup(
            body="robot", group=f"{side}_arm", joints=tuple(part.arm_for(side)[1].joints)
        )
    for name, joints in JOINT_GROUPS.items():
        groups[f"person.{name}"] = JointGroup(body="person", group=name, joints=tuple(joints))
    return groups


def check_mount(s: Scope) -> None:
    """``mount_on``, ``only_when_mounted`` and ``mount_base``, and a grip for every tool."""
    spec = s.spec
    mount = spec.robot.mount_on
    if mount is not None:
        if mount not in spec.scene.furniture:
            s.problem(("robot", "mount_on"), f"unknown furniture '{mount}'; {expected(spec.scene.furniture, mount)}")
        elif mount in s.furniture and s.robot.part.mountable and not s.furniture[mount].part.mount_link:
            s.problem(("robot", "mount_on"), f"furniture '{mount}' has no mount_link for the robot")
    for name, use in spec.scene.furniture.items():
        if use.only_when_mounted and name != mount:
            s.problem(
                ("scene", "furniture", name, "only_when_mounted"),
                f"furniture '{name}' is only_when_mounted but the robot mounts on {repr(mount) if mount else 'nothing'} "
                "(robot.mount_on); only the mount furniture can be left out for robots that stand on the floor",
            )
    if spec.robot.mount_base == "search":
        _check_searched_mount(s, mount)
    for name, use in spec.tools.items():
        _check_grip(s, name, use.part, use.grip)


def _check_grip(s: Scope, name: str, part: str, grip: str | None) -> None:
    """A grip for tool ``name``: the robot's ``grip``, or the robot's or the tool part's for this
    robot (not both). The remedy never sends the user to edit a shipped file: a shipped robot gets
    its grip from the tool part in the user's library."""
    tool = s.tools.get(name)
    if tool is None:  # an unknown tool part: already a problem
        return
    robot = s.robot.part
    grips = list(robot.grips)
    if grip is not None:
        if grip not in robot.grips:
            s.problem(
                ("tools", name, "grip"),
                f"robot '{s.robot_name}' has no grip '{grip}' for tool '{name}'; its grips: {one_of(grips)}"
                f"{did_you_mean(grip, grips)} (or remove tools.{name}.grip and give the tool part its own grip for "
                f"{s.robot_name}: grips: {{{s.robot_name}: ...}} in {tool.shown})",
            )
        return
    own = tool.part.grips.get(s.robot_name)
    if part in robot.grips and own is not None:
        s.problem(
            ("tools", name, "part"),
            f"tool '{name}': robot '{s.robot_name}' holds '{part}' by two grips, grips.{part} in {s.robot.shown} "
            f"and grips.{s.robot_name} in {tool.shown}; remove one",
        )
    elif part not in robot.grips and own is None:
        s.problem(("tools", name, "part"), _no_grip(s, name, tool, grips))


def _no_grip(s: Scope, name: str, tool: LoadedPart, grips: list[str]) -> str:
    """What to do about a tool no grip holds: give the tool part a grip for this robot (in the
    user's library; a shipped tool copied there first), or reuse one of the robot's grips."""
    robot, part = s.robot_name, tool.part.name
    example = f"grips: {{{robot}: {{position_m: [x, y, z], rpy_rad: [r, p, y]}}}}"
    frame = f"the tool frame in {robot}'s tool-mount frame"
    if is_shipped(tool.path):
        give = f"copy {tool.shown} into your library as tools/<new name>.yaml and add {example} ({frame})"
    else:
        give = f"add {example} to {tool.shown} ({frame})"
    if not is_shipped(s.robot.path):
        give += f", or a grip '{part}' under grips: in {s.robot.shown}"
    return (
        f"robot '{robot}' has no grip for tool '{name}' (part '{part}'): {give}; or set tools.{name}.grip to one of "
        f"{robot}'s grips: {one_of(grips)}{did_you_mean(part, grips)}"
    )


def check_arm_rest(s: Scope) -> None:
    """``per_robot.<robot>.arm_rest_rad``: one value per joint of the one acting arm."""
    rest = s.spec.robot.arm_rest_for(s.robot_name)
    if rest is None:
        return
    where = ("robot", "per_robot", s.robot_name, "arm_rest_rad")
    if len(s.sides) > 1:
        s.problem(
            where,
            "arm_rest_rad is the acting arm's rest in a task acting with one arm; this task acts with both "
            f"arms of '{s.robot_name}' (set rest_rad per arm in {s.robot.shown})",
        )
        return
    joints = s.robot.part.arm_for(s.sides[0])[1].joints
    if len(rest) != len(joints):
        s.problem(
            where,
            f"arm_rest_rad has {len(rest)} values but the arm of '{s.robot_name}' has {len(joints)} "
            f"joints ({', '.join(joints)})",
        )


def _check_searched_mount(s: Scope, mount: str | None) -> None:
    """``mount_base: search`` carries the mount furniture under the searched base: it needs one,
    only_when_mounted, and without a placement of its own."""
    use = s.spec.scene.furniture.get(mount) if mount else None
    if mount is None:
        s.problem(
            ("robot", "mount_base"),
            "mount_base 'search' carries the mount furniture under the searched base, "
            "but robot.mount_on names no furniture; set robot.mount_on or use mount_base: furniture",
        )
    elif use is not None and not use.only_when_mounted:
        s.problem(
            ("robot", "mount_base"),
            f"mount_base 'search' places furniture '{mount}' under a mounted robot's base, "
            f"so without one it has no place: set scene.furniture.{mount}.only_when_mounted: true",
        )
    elif use is not None:
        for field in ("position_m", "rpy_deg", "position_noise_m"):
            if field in use.model_fields_set:
                s.problem(
                    ("scene", "furniture", mount, field),
                    f"furniture '{mount}' is carried under the robot's searched base (robot.mount_base: search), "
                    f"so its {field} is not used; remove it (move the base search instead)",
                )


def base_goals(s: Scope) -> list[BaseGoal]:
    """The base search's goals: a resolved point, an offset (m) and the arm that should reach it."""
    spec = s.spec
    own = spec.robot.per_robot.get(s.robot_name)
    where = (
        ("robot", "per_robot", s.robot_name, "base_search")
        if own is not None and own.base_search is not None
        else ("robot", "base_search")
    )
    search = spec.robot.search_for(s.robot_name)
    goals = []
    for i, g in enumerate(search.goals):
        point = s.point(g.point, where + ("goals", i, "point"))
        if point is not None:
            goals.append(
                BaseGoal(
                    point=point,
                    offset_m=g.offset_m,
                    oriented=g.oriented,
                    required=g.required,
                    arm=(g.arm or "right") if len(s.sides) > 1 else s.sides[0],
                )
            )
    for i, g in enumerate(search.goals):
        if g.arm is not None and spec.robot.arm != "both":
            s.problem(
                where + ("goals", i, "arm"),
                f"a goal names an arm only in a task acting with both arms (robot.arm: both); this task's arm is '{spec.robot.arm}'",
            )
    return goals

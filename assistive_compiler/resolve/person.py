"""The ``person`` section: joint angles, control, impairments, the settle stage, the seat.

Checks every person joint named in ``joints_deg``, ``randomize_deg`` and ``settle.then`` against
the person URDF's movable joints and their limits (degrees in the spec, radians in the URDF), the
joint groups of ``control`` (policy and compliant joints), impairments and ``settle.then.dynamic``,
and the furniture the person sits on. Produces the person's policy joints
(``Scope.policy_joints``: URDF joint names in order, what ``person.policy`` refers to).
"""

from __future__ import annotations

import math

from ..spec.models import Uniform
from .located import expected
from .scope import Scope


def _deg_range(lower: float | None, upper: float | None) -> str:
    return (
        f"[{math.degrees(lower):.0f}°, {math.degrees(upper):.0f}°]"
        if lower is not None and upper is not None
        else "unlimited"
    )


def check_person(s: Scope) -> None:
    _check_joint_angles(s)
    _check_control(s)
    _check_settle_stage(s)
    _check_seat(s)


def _check_joint_angles(s: Scope) -> None:
    person = s.spec.person
    movable = s.person_urdf.movable_joints
    for section, values in (("joints_deg", person.joints_deg), ("randomize_deg", person.randomize_deg)):
        for name, value in values.items():
            path = ("person", section, name)
            if name not in movable:
                s.problem(path, f"unknown person joint '{name}'; {expected(movable, name)}", key=True)
                continue
            j = movable[name]
            lows, highs = value.uniform if isinstance(value, Uniform) else (value, value)
            for deg in (lows, highs):
                rad = math.radians(deg)
                if j.lower is not None and not (j.lower - 1e-9 <= rad <= j.upper + 1e-9):
                    s.problem(path, f"{name} = {deg:g}° is outside the joint's limits {_deg_range(j.lower, j.upper)}")
                    break


def _check_control(s: Scope) -> None:
    """Policy and compliant joint groups, and the joints impairments act on; fills the policy joints."""
    person = s.spec.person
    for i, ref in enumerate(person.control.policy_joints):
        group = s.joints(ref, ("person", "control", "policy_joints", i))
        if group:
            if group.body != "person":
                s.problem(
                    ("person", "control", "policy_joints", i), f"policy_joints must be person joint groups, got '{ref}'"
                )
            else:
                s.policy_joints += [j for j in group.joints if j not in s.policy_joints]
    if person.control.compliant:
        for i, ref in enumerate(person.control.compliant.joints):
            s.joints(ref, ("person", "control", "compliant", "joints", i))
    for i, choice in enumerate(person.impairments.choices):
        for k, ref in enumerate(getattr(choice, "joints", [])):
            s.joints(ref, ("person", "impairments", "choices", i, "joints", k))


def _check_settle_stage(s: Scope) -> None:
    """``placement.settle.then``: person joint groups that move, and joint angles within limits."""
    person = s.spec.person
    stage = person.placement.settle.then if person.placement.settle else None
    if stage is None:
        return
    movable = s.person_urdf.movable_joints
    base = ("person", "placement", "settle", "then")
    for i, ref in enumerate(stage.dynamic):
        group = s.joints(ref, base + ("dynamic", i))
        if group and group.body != "person":
            s.problem(base + ("dynamic", i), f"dynamic joints must be person joint groups, got '{ref}'")
    for name, deg in stage.joints_deg.items():
        if name not in movable:
            s.problem(
                base + ("joints_deg", name), f"unknown person joint '{name}'; {expected(movable, name)}", key=True
            )
        elif movable[name].lower is not None and not (
            movable[name].lower - 1e-9 <= math.radians(deg) <= movable[name].upper + 1e-9
        ):
            s.problem(
                base + ("joints_deg", name),
                f"{name} = {deg:g}° is outside the joint's limits {_deg_range(movable[name].lower, movable[name].upper)}",
            )


def _check_seat(s: Scope) -> None:
    seat = s.spec.person.placement.seated_on
    if seat is None:
        return
    path = ("person", "placement", "seated_on")
    if seat not in s.spec.scene.furniture:
        s.problem(path, f"unknown furniture '{seat}'; {expected(s.spec.scene.furniture, seat)}")
    elif s.conditional(seat, path):
        pass
    elif seat in s.furniture and not s.furniture[seat].part.seat_link:
        s.problem(path, f"furniture '{seat}' (part '{s.furniture[seat].part.name}') has no seat_link to sit on")

"""The paper's seven human-preference costs c_k ≤ 0 (Erickson et al. 2020, paper §III-E).

r_H = Σ_k α_k·ω_k·c_k: a spec's ``preferences.active`` sets α_k = 1 for the costs it lists, and ω_k
defaults to the paper's weights (0.25, 0.01, 0.05, 1.0, 1.0, 0.01, 0.01). The compiler turns each
active cost into a reward term named ``preference_<name>`` so ``info`` reports it like any term.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from pydantic import Field

from .registry import BodiesRef, BodyRef, Params, ParticlesRef, PointRef, term

if TYPE_CHECKING:
    from ..references import PointHandle
    from .reads import SceneReads


class Velocity(Params):
    of: list[PointRef] = Field(min_length=1)


class ForceNonTarget(Params):
    onto: BodiesRef
    by: BodiesRef
    target_tool: BodiesRef = Field(default_factory=list)
    target: PointRef | None = None
    target_radius_m: float = Field(0.025, gt=0)


class HighForce(Params):
    tool: BodiesRef
    onto: BodiesRef
    target: PointRef | None = None
    target_radius_m: float = Field(0.025, gt=0)
    threshold_n: float = Field(10.0, gt=0)


class ParticleSet(Params):
    particles: ParticlesRef


class DressingForce(Params):
    cloth: BodiesRef
    onto: BodiesRef


class Pressure(Params):
    tools: list[BodyRef] = Field(min_length=1)
    onto: BodiesRef
    contact_distance_m: float = Field(0.01, gt=0)


def _tool_force(snap: SceneReads, tool: list[str], on: list[str], target: PointHandle | None, radius: float) -> float:
    if target is None:
        return snap.contact_force(tool, on)
    return snap.contact_force(tool, on, near=target, radius=radius)


@term("velocity", "preference", Velocity)
def velocity(snap: SceneReads, p: Velocity) -> float:
    """C_v = −Σ‖v‖ over the listed points' linear speeds (m/s): move slowly near a person."""
    return -sum(math.hypot(*snap.velocity(point).tolist()) for point in p.of)


@term("force_nontarget", "preference", ForceNonTarget)
def force_nontarget(snap: SceneReads, p: ForceNonTarget) -> float:
    """C_f = −(F_total − F_target) (N): contact force on the person away from the task target.

    F_total pools the contacts of ``by`` on ``onto``. F_target is the force of ``target_tool`` within
    ``target_radius_m`` of ``target`` (0 when no target is given, as in feeding: all force counts).
    """
    total = snap.contact_force(p.by, p.onto)
    at_target = (
        _tool_force(snap, p.target_tool, p.onto, p.target, p.target_radius_m) if p.target_tool and p.target else 0.0
    )
    return -float(total - at_target)


@term("high_force", "preference", HighForce)
def high_force(snap: SceneReads, p: HighForce) -> float:
    """C_hf = −F if the tool's force on the person (near the target) is ≥ threshold, else 0 (N)."""
    force = _tool_force(snap, p.tool, p.onto, p.target, p.target_radius_m)
    return -float(force) if force >= p.threshold_n else 0.0


@term("food_hit", "preference", ParticleSet)
def food_hit(snap: SceneReads, p: ParticleSet) -> float:
    """C_fd = −(particles that first touched the person this step) (count): spills on the person."""
    return -float(snap.particle_events(p.particles).hit)


@term("food_velocity", "preference", ParticleSet)
def food_velocity(snap: SceneReads, p: ParticleSet) -> float:
    """C_fdv = −Σ speeds of particles consumed this step (m/s): food entering the mouth too fast."""
    return -float(snap.particle_events(p.particles).consumed_speed_sum)


@term("dressing_force", "preference", DressingForce)
def dressing_force(snap: SceneReads, p: DressingForce) -> float:
    """C_d = −Σ‖f‖ of the garment's contact forces on the person (N)."""
    return -float(snap.contact_force(p.cloth, p.onto))


@term("pressure", "preference", Pressure)
def pressure(snap: SceneReads, p: Pressure) -> float:
    """C_p = −Σ_tools F/n (N per contact): force spread over few contacts hurts (0 when n = 0)."""
    cost = 0.0
    for tool in p.tools:
        force, count = snap.contact_force_and_count(tool, p.onto, p.contact_distance_m)
        if count:
            cost -= force / count
    return cost

"""Reward terms. Each returns an unweighted value in natural units; the spec's weight gives the
sign and scale (e.g. a distance in metres with weight −1 penalises distance). The reward is
Σ weight·value, and ``info["terms"]`` reports every value."""

from __future__ import annotations

import math
from typing import Literal

from .registry import BodiesRef, Params, ParticlesRef, PointRef, term


class Distance(Params):
    a: PointRef
    b: PointRef


class ActionNorm(Params):
    agent: Literal["robot", "human", "all"] = "all"


class ParticleSet(Params):
    particles: ParticlesRef


class ContactForce(Params):
    a: BodiesRef
    b: BodiesRef


@term("distance", "reward", Distance)
def distance(snap, p) -> float:
    """Euclidean distance between two points (m)."""
    return math.dist(snap.position(p.a), snap.position(p.b))


@term("action_norm", "reward", ActionNorm)
def action_norm(snap, p) -> float:
    """‖a‖₂ of the raw (unclipped) action of ``agent`` — the paper's action penalty input."""
    return math.hypot(*snap.action(p.agent))


@term("particles_consumed", "reward", ParticleSet)
def particles_consumed(snap, p) -> float:
    """Particles of the set consumed this step (count), e.g. food that entered the mouth."""
    return float(snap.particle_events(p.particles).consumed)


@term("particles_lost", "reward", ParticleSet)
def particles_lost(snap, p) -> float:
    """Particles of the set lost this step (count), e.g. food spilled from the spoon."""
    return float(snap.particle_events(p.particles).lost)


@term("contact_force", "reward", ContactForce)
def contact_force(snap, p) -> float:
    """Sum of contact normal forces between bodies ``a`` and ``b`` this step (N)."""
    return float(snap.contact_force(p.a, p.b))

"""Where the physics of an env step goes: Bullet's own profiler over one episode, its zones summed
into stages (constraint solving, contact and joint row setup, collision detection, soft bodies,
multibody dynamics), and a census of the contact points each pair of bodies brings to the solver.

Bullet's profiler (``STATE_LOGGING_PROFILE_TIMINGS``) records the engine's timed zones around its
stages. Their intervals are nested by time, and each stage's share of ``stepSimulation`` is the
time of its outermost zones. The profiler's own cost inflates every zone a little and evenly, so
the shares, not the absolute times, are what to read. ``bench`` reports the shares
(``physics_stages``); ``benchmarks/physics_profile.py`` adds the contact census and the split of a
step between the physics and our Python.
"""

from __future__ import annotations

import collections
import json
import re
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np
import pybullet as pb

from .compile.external_checks import captured_c_output

STAGES = {
    "solver iterations": ["solveGroupCacheFriendlyIterations"],
    "solver setup (contact and joint rows)": ["solveGroupCacheFriendlySetup"],
    "collision: pair processing (narrowphase)": ["processAllOverlappingPairs"],
    "collision: bounding boxes (broadphase)": ["updateAabbs", "calculateOverlappingPairs"],
    "soft bodies": [
        "solveSoftConstraints",
        "predictUnconstraintMotionSoftBody",
        "softBodySelfCollision",
        "btSoftBody",
        "integrateTransformsSoftBody",
        "solveDeformableConstraints",
        "btDeformable",
    ],
    "multibody dynamics (forward, integrate)": [
        "btMultiBody stepVelocities",
        "btMultiBody stepPositions",
        "computeAccelerationsArticulatedBodyAlgorithmMultiDof",
    ],
}
"""Bullet profiler zones summed into each stage (a zone counts once: its nearest named ancestor wins)."""

STEP_ZONE = "CMD_STEP_FORWARD_SIMULATION"
"""The zone around one ``stepSimulation`` call: the whole the shares are of."""


_COUNTED = (STEP_ZONE, *(zone for zones in STAGES.values() for zone in zones))
"""Prefixes of the zones :func:`stage_shares` reads; the rest (most of a trace: every pybullet call's
client command) are skipped. Leaving them out changes no share: a zone that counts toward no stage
passes its ancestor's stage on unchanged."""


def trace_events(path: str | Path, names: tuple[str, ...] | None = None) -> Iterator[dict]:
    """The events of a Chrome-format trace that Bullet's profiler wrote, read one line at a time
    (Bullet writes one event a line); with ``names``, only the events of zones whose names start
    with one of them. A 400-step episode's trace holds over a million events; parsed as one
    document they took a gigabyte (``bench``'s peak memory was this)."""
    with open(path) as f:
        for line in f:
            at = line.find('"name":"')
            if at < 0 or (names is not None and not line.startswith(names, at + 8)):
                continue
            yield json.loads(line.strip().rstrip(","))


def _intervals(events: Iterable[dict]) -> list[tuple[float, float, str]]:
    """(start µs, end µs, zone) of every profiler zone that :func:`stage_shares` reads, numbered
    suffixes dropped, sorted to nest."""
    opened: dict[str, float] = {}
    out = []
    for e in events:
        name = e["name"]
        if not name.startswith(_COUNTED):
            continue
        if e["ph"] == "B":
            opened[name] = e["ts"]
        elif e["ph"] == "E" and name in opened:
            out.append((opened.pop(name), e["ts"], re.sub(r"\d+$", "", name)))
    out.sort(key=lambda iv: (iv[0], -iv[1]))
    return out


def stage_shares(trace: dict | Iterable[dict]) -> dict[str, float]:
    """Each stage's share of stepSimulation's time in a Chrome-format trace of Bullet's profiler (the
    parsed document, or its events: :func:`trace_events`); the remainder is ``other``; empty when the
    trace holds no step."""
    step = 0.0
    spent: collections.Counter = collections.Counter()
    stack: list[tuple[float, float, str, str | None]] = []  # (start, end, zone, stage it counts toward)
    events = trace["traceEvents"] if isinstance(trace, dict) else trace
    for start, end, zone in _intervals(events):
        while stack and stack[-1][1] <= start:
            stack.pop()
        inherited = stack[-1][3] if stack else None
        if zone == STEP_ZONE:
            step += end - start
        own = next((stage for stage, zones in STAGES.items() if any(zone.startswith(z) for z in zones)), None)
        if own is not None and inherited is None:
            spent[own] += end - start
        stack.append((start, end, zone, inherited or own))
    if not step:
        return {}
    shares = {stage: spent[stage] / step for stage in STAGES}
    shares["other"] = max(0.0, 1.0 - sum(shares.values()))
    return shares


def profile_episode(env, actions: list[np.ndarray], seed: int) -> tuple[dict[str, float], dict[str, float]]:
    """One seeded episode of ``actions`` under Bullet's profiler: each stage's share of the physics
    (:func:`stage_shares`) and the contact points per env step by body pair (``"a – b"``, the last
    physics step's, most first)."""
    c = env.client
    contacts: collections.Counter = collections.Counter()
    env.reset(seed=seed)
    with tempfile.TemporaryDirectory() as tmp:
        trace_file = Path(tmp) / "trace.json"
        log = pb.startStateLogging(pb.STATE_LOGGING_PROFILE_TIMINGS, str(trace_file), physicsClientId=c)
        try:
            for a in actions:
                env.step(a)
                for point in pb.getContactPoints(physicsClientId=c):
                    pair = sorted((env.link_owner(point[1], point[3]), env.link_owner(point[2], point[4])))
                    contacts[" – ".join(pair)] += 1
        finally:
            with captured_c_output():  # Bullet prints "Writing N timings" from C; dropped
                pb.stopStateLogging(log, physicsClientId=c)
        written = sorted(Path(tmp).glob(f"{trace_file.name}_*.json"))  # Bullet appends _<thread>.json
        shares = stage_shares(trace_events(written[0], _COUNTED)) if written else {}
    steps = max(1, len(actions))
    return shares, {pair: n / steps for pair, n in contacts.most_common()}

"""What a compiled task's scene looks like after a reset, in words and numbers: every body and link
with its world position and the world direction of each of its frame's axes, the robot's links
by role, the tools, targets, markers and particles.

:func:`describe_scene` reads an :class:`~assistive_compiler.runtime.env.AssistiveEnv` (only reads:
nothing is moved); ``assistive-compiler describe`` prints it. Units: metres, world frame (z up);
the person faces the world direction given in ``person.faces``.
"""

from __future__ import annotations

import numpy as np

from .record.capture import SceneReader
from .rotation import quat_matrix

AXES = "xyz"


AXIS_NAMED_WITHIN_DEG = 0.5
"""A frame axis is named (``+x``) only within this angle of a world axis; further off, its
components show the turn (a head turned 4.6° reads ``(1.00, -0.08, 0.00)``, not ``+x``)."""

_NAMED_COS = float(np.cos(np.radians(AXIS_NAMED_WITHIN_DEG)))


def axis_direction(vector) -> str:
    """A unit vector in words: ``+x``, ``-z`` when it lies within :data:`AXIS_NAMED_WITHIN_DEG`
    (0.5°) of a world axis, else its components (``(0.71, 0.00, -0.71)``)."""
    v = np.asarray(vector, dtype=float)
    k = int(np.argmax(np.abs(v)))
    if abs(v[k]) >= _NAMED_COS:
        return f"{'+' if v[k] > 0 else '-'}{AXES[k]}"
    return "(" + ", ".join(f"{c:.2f}" for c in v) + ")"


def _rounded(v) -> list[float]:
    return [round(float(c), 4) + 0.0 for c in v]


def _marker_set(env, name: str) -> dict:
    where, _ = env.marker_state(name)
    return {"name": name, "count": len(where), "centroid_m": _rounded(np.mean(where, axis=0)) if len(where) else None}


def describe_scene(env) -> dict:
    """The scene of ``env`` as it is now (call after ``reset``): a JSON-able dict (see the module doc)."""
    m = env.manifest
    reader = SceneReader(env)
    pos, quat = reader.link_poses()
    person = env.person_body
    parked = {v.body for v in m.person.variants if v.body != person}
    bodies = []
    for body in reader.bodies:
        if body["kind"] == "garment":
            bodies.append({"name": body["name"], "kind": "garment", "links": []})
            continue
        entry = {"name": body["name"], "kind": body["kind"], "shown": body["name"] not in parked, "links": []}
        if entry["shown"]:
            for link in body["links"]:
                k = reader.links.index([body["name"], link])
                rot = quat_matrix(quat[k])
                entry["links"].append(
                    {
                        "name": link,
                        "position_m": _rounded(pos[k]),
                        "axes": {AXES[a]: axis_direction(rot[:, a]) for a in range(3)},
                    }
                )
        bodies.append(entry)
    person_base = next(b for b in reader.bodies if b["name"] == person)["links"][0]  # base link first
    person_rot = quat_matrix(quat[reader.links.index([person, person_base])])  # the person faces its base's -y
    targets = reader.target_positions(pos, quat)
    out = {
        "task": m.task,
        "robot": m.robot_name,
        "gym_id": m.gym_id,
        "person": {
            "variant": next(v.name for v in m.person.variants if v.body == person),
            "body": person,
            "faces": axis_direction(-person_rot[:, 1]),
            "base_link": person_base,
        },
        "robot_links": {role: link for role, link in sorted(m.robot.links.items())},
        "tools": [
            {
                "body": t.body,
                "held_by": f"robot.{t.parent_link}",
                "held_as": "welded" if t.welded else "constraint",
                "links": dict(sorted(t.links.items())),
            }
            for t in m.tools
        ],
        "targets": [
            {
                "name": name,
                "position_m": _rounded(targets[k]),
                "on": f"{m.targets[name].body}.{m.targets[name].link}",
                "drawn_on_surface": m.targets[name].surface,
            }
            for k, name in enumerate(reader.targets)
        ],
        "markers": [_marker_set(env, s.name) for s in m.markers],
        "particles": [
            {
                "name": p.name,
                "count": p.count,
                "centroid_m": _rounded(np.mean(env.particle_state(p.name)[0], axis=0)),
            }
            for p in m.particles
        ],
        "bodies": bodies,
    }
    return out


_HELD_AS = {
    "welded": "welded to it: links of the robot's body",
    "constraint": "a fixed constraint of at most 500 N",
}


def describe_text(d: dict) -> str:
    """:func:`describe_scene`'s dict as the lines ``describe`` prints."""
    p = d["person"]
    lines = [
        f"{d['task']} for {d['robot']}: person {p['variant']} (body {p['body']}), facing {p['faces']}. "
        "World frame, metres, z up; each link's frame axes given as the world direction they point in."
    ]
    lines.append(
        "robot links by role: " + ", ".join(f"{role} = robot.{link}" for role, link in d["robot_links"].items())
    )
    for t in d["tools"]:
        lines.append(
            f"tool {t['body']}: held by {t['held_by']} ({_HELD_AS[t['held_as']]}); links "
            + ", ".join(f"{k} = {v}" for k, v in t["links"].items())
        )
    for t in d["targets"]:
        where = "drawn on the surface of " if t["drawn_on_surface"] else "on "
        lines.append(f"target {t['name']}: {_xyz(t['position_m'])} ({where}{t['on']})")
    for s in d["markers"]:
        lines.append(
            f"markers {s['name']}: {s['count']}" + (f", centroid {_xyz(s['centroid_m'])}" if s["centroid_m"] else "")
        )
    for s in d["particles"]:
        lines.append(f"particles {s['name']}: {s['count']}, centroid {_xyz(s['centroid_m'])}")
    for b in d["bodies"]:
        if b["kind"] == "garment":
            lines.append(f"\n{b['name']} (garment)")
            continue
        if not b["shown"]:
            lines.append(f"\n{b['name']} ({b['kind']}): parked, not this episode's person")
            continue
        merged = (
            (
                "; the person's other links are static in this task and merged into these "
                "(all 43 and their frames: docs/person.md)"
            )
            if b["kind"] == "person" and len(b["links"]) < 43
            else ""
        )
        lines.append(f"\n{b['name']} ({b['kind']}, {len(b['links'])} links{merged})")
        width = max(len(link["name"]) for link in b["links"])
        wide = max(len(v) for link in b["links"] for v in link["axes"].values()) + 1
        lines.append(f"  {'link':<{width}}  {'position (m)':<26}  {'+x':<{wide}} {'+y':<{wide}} +z")
        for link in b["links"]:
            a = link["axes"]
            lines.append(
                f"  {link['name']:<{width}}  {_xyz(link['position_m']):<26}  {a['x']:<{wide}} {a['y']:<{wide}} {a['z']}"
            )
    return "\n".join(lines)


def _xyz(v) -> str:
    return "(" + ", ".join(f"{c:+.3f}" for c in v) + ")"

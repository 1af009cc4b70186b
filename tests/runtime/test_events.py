"""A reset as the manifest's ordered events (runtime/events.py), the components' one protocol
(runtime/component.py), and reading artifacts written before the events existed (format 1)."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pybullet as pb
import pytest

from assistive_compiler.artifact import (
    ComponentResetEvent,
    FloorFrictionEvent,
    FurnitureNoiseEvent,
    Manifest,
    PersonVariantEvent,
    RobotStartEvent,
    SurfaceTargetsEvent,
    reset_events,
)
from assistive_compiler.errors import SpecError
from assistive_compiler.runtime.env import AssistiveEnv


def test_feeding_compiles_its_reset_into_events_in_draw_order(artifact):
    """Feeding draws the person, holds it, clears term memories, starts the robot, moves the bowl
    (its spec's position_noise_m) and draws the floor's friction, then puts the food in the spoon."""
    assert Manifest.read(artifact).events == [
        PersonVariantEvent(),
        ComponentResetEvent(component="person"),
        ComponentResetEvent(component="reward_terms"),
        RobotStartEvent(),
        FurnitureNoiseEvent(body="bowl", half_width=(0.05, 0.05, 0.0)),
        FloorFrictionEvent(low=0.025, high=0.5),
        ComponentResetEvent(component="particles"),
    ]


def test_reset_events_lists_only_the_parts_a_task_has():
    everything = reset_events(
        surface_targets=True,
        markers=True,
        furniture_noise=[("bowl", (0.1, 0.0, 0.0))],
        floor_friction=(0.1, 0.2),
        particles=True,
        garments=True,
    )
    assert [(e.event, getattr(e, "component", None)) for e in everything] == [
        ("person_variant", None),
        ("reset", "person"),
        ("surface_targets", None),
        ("reset", "markers"),
        ("reset", "reward_terms"),
        ("robot_start", None),
        ("furniture_noise", None),
        ("floor_friction", None),
        ("reset", "particles"),
        ("reset", "garments"),
    ]
    assert SurfaceTargetsEvent() in everything


def test_furniture_noise_and_floor_friction_are_drawn_within_their_ranges(env):
    """Over seeds the bowl moves within ±5 cm in x and y of its nominal place and not in z, to both
    sides; the floor's friction lies in [0.025, 0.5] and differs between episodes."""
    m, w = env.manifest, env.world
    nominal = np.asarray(m.body("bowl").position)
    offsets, frictions = [], []
    for seed in range(12):
        env.reset(seed=seed)
        offsets.append(np.asarray(w.base_frame(w.bodies["bowl"])[0]))  # the URDF base frame, not the COM
        frictions.append(pb.getDynamicsInfo(w.ground, -1, physicsClientId=w.client)[1])
    offsets = np.array(offsets) - nominal
    assert np.all(np.abs(offsets[:, :2]) <= 0.05 + 1e-6) and np.allclose(offsets[:, 2], 0.0, atol=1e-6)
    assert (offsets[:, :2] > 0.005).any(axis=0).all() and (offsets[:, :2] < -0.005).any(axis=0).all()
    assert all(0.025 <= f <= 0.5 for f in frictions) and len(set(np.round(frictions, 6))) == len(frictions)


def test_events_left_out_of_the_manifest_are_not_applied(artifact):
    """The env applies the manifest's events and nothing else: without the bowl's noise event the
    bowl stays exactly where it was compiled, while the rest of the reset still happens."""
    full = Manifest.read(artifact)
    still = full.model_copy(update={"events": [e for e in full.events if e.event != "furniture_noise"]})
    env = AssistiveEnv(artifact, manifest=still)
    try:
        for seed in (0, 1, 2):
            _, info = env.reset(seed=seed)
            pos = env.base_pose("bowl")[0]
            assert pos == pytest.approx(still.body("bowl").position, abs=1e-6)
            assert info["person_variant"] in ("male_50th", "female_50th")
    finally:
        env.close()


def test_reset_info_names_what_the_events_drew(env):
    _, info = env.reset(seed=5, options={"person_variant": "female_50th"})
    assert info["person_variant"] == "female_50th" and env.person_variant == "female_50th"
    variant = next(v for v in env.manifest.person.variants if v.name == "female_50th")
    start = variant.starts[info["start"]]
    assert np.allclose(env.base_pose("robot")[0], start.base_position, atol=1e-6)
    assert info["impairment"]["kind"] in {i.kind for i in env.manifest.person.impairments}


def _as_format_1(manifest: Manifest) -> dict:
    """``manifest`` as a format-1 file held it: no events; floor friction in ``sim``; every body's
    position noise (zero unless an event moved it) on the body."""
    data = json.loads(manifest.to_json())
    noise = {e.body: list(e.half_width) for e in manifest.events if isinstance(e, FurnitureNoiseEvent)}
    friction = next(e for e in manifest.events if isinstance(e, FloorFrictionEvent))
    data["sim"]["ground_friction"] = [friction.low, friction.high]
    for body in data["bodies"]:
        body["position_noise"] = noise.get(body["name"], [0.0, 0.0, 0.0])
    del data["events"]
    data["format_version"] = 1
    return data


def _write_hashed(artifact, data: dict) -> None:
    """Write ``data`` as the artifact's manifest with the content hash its format recorded."""
    import hashlib

    files = b"".join((artifact / b["urdf"]).read_bytes() for b in sorted(data["bodies"], key=lambda b: b["urdf"]))
    blank = json.dumps(data | {"content_hash": "", "input_hash": ""}, indent=1, sort_keys=True) + "\n"
    data["content_hash"] = hashlib.sha256(files + blank.encode()).hexdigest()
    (artifact / "manifest.json").write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")


def test_a_format_1_artifact_reads_as_today_s_and_keeps_its_hash_checked(artifact, tmp_path):
    """An artifact compiled before the events existed (a run directory's, to --resume it) reads
    with the events its runtime applied, passes its content-hash check, and hashes as today's
    compile of the same task; an edit to it is still caught."""
    today = Manifest.read(artifact)
    old = tmp_path / "old"
    shutil.copytree(artifact, old)
    _write_hashed(old, _as_format_1(today))
    read = Manifest.read(old, verify=True)
    assert read.format_version == 2 and read.events == today.events and read.sim == today.sim
    assert read.hash_of(old) == today.content_hash

    data = json.loads((old / "manifest.json").read_text())
    data["sim"]["ground_friction"] = [0.025, 0.6]  # edited after compiling, hash left as it was
    (old / "manifest.json").write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    with pytest.raises(SpecError, match="files differ from what was compiled"):
        Manifest.read(old, verify=True)

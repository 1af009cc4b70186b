"""Particles resting in a container (``particles.<set>.rest``), on the shipped Drinking task for Jaco
with real compiles and real pybullet: water in the held, upright cup is carried unsimulated and
stays; simulated water in a held, still cup comes to rest and is carried within a few steps at
the shipped 4 solver sub-steps, upright or tilted, and a tilted cup keeps it carried until it
turns further; tipping the cup past the limits puts it back into the physics, and past ~90° most
of it pours out; a cup turned upright again carries what is left; seeded episodes that pour
replay bit for bit; renders draw carried water where it is; a rest container must be a tool with one.
Feeding with resting food (benchmarks/specs/feeding_food_rests.yaml, Jaco): the food is simulated
from the reset, rides in the spoon once it rests and is simulated near the person, where it is
eaten; `simulated_near` names a known body.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pybullet as pb
import pytest

from assistive_compiler.cli import main
from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.paths import display, specs_dir
from assistive_compiler.policies.scripted import ScriptedPolicy
from assistive_compiler.runtime.env import AssistiveEnv

DRINKING = specs_dir() / "tasks" / "drinking.yaml"


@pytest.fixture(scope="module")
def artifact(tmp_path_factory):
    return compile_task(DRINKING, "jaco", tmp_path_factory.mktemp("rest") / "drinking-jaco").out_dir


@pytest.fixture
def env(artifact):
    e = AssistiveEnv(artifact)
    yield e
    e.close()


def water_in_cup_frame(env) -> np.ndarray:
    """Where the water is (carried particles where they are carried), in the cup frame (m)."""
    w, c = env.world, env.client
    cup = w.bodies["cup"]
    pos, orn = w.base_frame(cup)
    inv = pb.invertTransform(pos, orn)
    ps = env.particles
    out = []
    for k, pid in enumerate(w.particles["water"]):
        if ps.carried["water"][k]:
            out.append(ps.carried_at["water"][k])
        else:
            p = pb.getBasePositionAndOrientation(pid, physicsClientId=c)[0]
            out.append(pb.multiplyTransforms(*inv, p, (0, 0, 0, 1))[0])
    return np.array(out)


def inside_cup(env, slack: float = 0.0) -> np.ndarray:
    """Which particles are in the cup's inside cylinder, widened by ``slack`` (m): a heap leaning
    on a tilted wall presses a few millimetres into it (see templates/tools/cup.urdf.xacro)."""
    box = env.manifest.particles[0].outside_of
    local = water_in_cup_frame(env)
    return (
        (np.hypot(local[:, 0], local[:, 1]) <= box.radius + slack)
        & (local[:, 2] >= -box.radius)
        & (local[:, 2] <= box.height)
    )


def tip_cup(env, start_deg: float, end_deg: float, steps: int) -> None:
    """Turn the cup in the hand about its x axis from ``start_deg`` to ``end_deg`` away from its grip
    over ``steps`` env steps (the fixed constraint's child frame), the arm holding still. The grip
    frame is identity in the cup (its inertial sits at its frame origin)."""
    w, c = env.world, env.client
    cid = w.tool_constraints["cup"]
    for k in range(1, steps + 1):
        angle = math.radians(start_deg + (end_deg - start_deg) * k / steps)
        pb.changeConstraint(
            cid, jointChildFrameOrientation=pb.getQuaternionFromEuler([-angle, 0, 0]), maxForce=500, physicsClientId=c
        )
        env.step(np.zeros(env.action_space.shape))


def test_held_upright_cup_carries_its_water_for_a_whole_episode(env):
    env.reset(seed=0)
    assert env.particles.carried["water"].all()  # at rest in an upright cup from the reset on
    for _ in range(env.manifest.sim.episode_steps):
        _, _, _, truncated, info = env.step(np.zeros(env.action_space.shape))
        assert info["terms"]["water_drunk"] == 0 and info["terms"]["water_spilled"] == 0
    assert truncated
    assert env.particles.remaining("water") == 64 and env.particles.carried["water"].all()
    assert inside_cup(env).all()
    # Carried water is out of the physics: parked far away, touching nothing near the scene.
    c = env.client
    for pid in env.particle_ids("water"):
        assert pb.getBasePositionAndOrientation(pid, physicsClientId=c)[0][1] > 100


def test_parked_particles_are_put_back_up_before_they_reach_the_ground(env):
    """Carried (parked) water falls under the world's gravity far from the scene; every
    ``repark_steps`` env steps it goes back to its parking spot, so it never lands on the ground
    plane (where 64 resting contacts would cost solver work every physics step)."""
    env.reset(seed=0)
    w, c = env.world, env.client
    ids = w.particles["water"]
    assert env.particles.repark_steps == 31  # free fall from 50 m to 1 m: 3.16 s of 0.1 s env steps
    lowest = math.inf
    for _ in range(3 * env.particles.repark_steps):
        env.step(np.zeros(env.action_space.shape))
        assert env.particles.carried["water"].all()
        z = [pb.getBasePositionAndOrientation(pid, physicsClientId=c)[0][2] for pid in ids]
        lowest = min(lowest, min(z))
        assert not any(pb.getContactPoints(bodyA=pid, bodyB=w.ground, physicsClientId=c) for pid in ids)
    assert 1.0 < lowest < 40.0  # they did fall, tens of metres


def steps_until_carried(env, limit: int) -> int | None:
    """Zero-action env steps until all the water is carried (None: not within ``limit``)."""
    for k in range(1, limit + 1):
        env.step(np.zeros(env.action_space.shape))
        if env.particles.carried["water"].all():
            return k
    return None


def test_simulated_water_in_a_held_still_upright_cup_is_carried_within_a_few_steps(env):
    """At the shipped 4 solver sub-steps a particle or two of a resting heap rattle at several cm/s;
    the heap's mean speed still falls below the limit, so the water rests within a few steps."""
    assert env.manifest.sim.sub_steps == 4
    env.reset(seed=0)
    ps, ids = env.particles.sets[0][:2]
    env.particles._release(ps, ids)
    assert not env.particles.carried["water"].any()
    assert steps_until_carried(env, 10) is not None
    assert inside_cup(env).all() and env.particles.remaining("water") == 64


def test_water_at_rest_in_a_held_tilted_cup_is_carried_until_the_cup_turns_further(env):
    """Tipped 30° (past the 20° turn: simulated again, below the 45° tilt limit) and held, the
    water settles against the low side and is carried there; it stays carried while the cup is
    held, and turning the cup 25° further puts it back into the physics."""
    env.reset(seed=2)
    tip_cup(env, 0, 30, 5)
    assert steps_until_carried(env, 30) is not None
    w = env.world
    down = (
        np.asarray(pb.getMatrixFromQuaternion(w.base_frame(w.bodies["cup"])[1])).reshape(3, 3)[2] * -1.0
    )  # world −z in the cup frame
    downhill = down[:2] / np.linalg.norm(down[:2])
    assert (
        water_in_cup_frame(env)[:, :2].mean(axis=0) @ downhill > 0.01
    )  # the heap lies on the low side (it started centred)
    for _ in range(20):
        env.step(np.zeros(env.action_space.shape))
        assert env.particles.carried["water"].all()
    tip_cup(env, 30, 55, 3)
    assert not env.particles.carried["water"].any()


def test_tipping_past_the_limit_releases_the_water_and_past_90_degrees_pours_it(env):
    env.reset(seed=0)
    tip_cup(env, 0, 110, 10)
    assert not env.particles.carried["water"].any()
    for _ in range(20):
        env.step(np.zeros(env.action_space.shape))
    active = env.particles.active["water"]
    still_in = inside_cup(env) & active
    assert still_in.sum() <= 16, still_in.sum()  # most of it left the cup


def test_water_tipped_within_its_angle_of_repose_stays_and_rests_again_when_upright(env):
    env.reset(seed=1)
    tip_cup(env, 0, 40, 5)  # past the 20° limit: simulated again, but no spill at 40°
    assert not env.particles.carried["water"].any()
    for _ in range(10):
        env.step(np.zeros(env.action_space.shape))
    assert inside_cup(env, slack=0.005).all() and env.particles.remaining("water") == 64
    tip_cup(env, 40, 0, 5)  # back upright
    for _ in range(60):
        env.step(np.zeros(env.action_space.shape))
        if env.particles.carried["water"].all():
            break
    assert env.particles.carried["water"].all()
    assert inside_cup(env).all() and env.particles.remaining("water") == 64


@pytest.mark.slow
def test_a_seeded_pouring_episode_replays_bit_for_bit(env):
    """The scripted policy pours (water released, drunk, spilled, the rest carried again): the same
    seed gives the same observations, rewards and particle states, whatever ran before."""

    def episode(seed):
        obs, _ = env.reset(seed=seed)
        policy = ScriptedPolicy(env)
        trace = [obs]
        for _ in range(140):
            obs, reward, _, _, info = env.step(policy(obs))
            trace.append(np.concatenate([obs, [reward, info["success_metric"], env.particles.carried["water"].sum()]]))
        return np.concatenate(trace)

    first = episode(4)
    episode(7)
    assert np.array_equal(first, episode(4))
    assert env.success_metric > 0  # it did pour


def test_renders_draw_carried_water_in_the_cup(artifact):
    """Carried water is drawn where it is carried, as overlay dots: no body is created or moved."""
    e = AssistiveEnv(artifact, render_mode="rgb_array", render_size=(64, 48))
    try:
        e.reset(seed=0)
        w, c = e.world, e.world.client
        before = [
            pb.getBasePositionAndOrientation(b, physicsClientId=c) for b in range(pb.getNumBodies(physicsClientId=c))
        ]
        e.render()
        after = [
            pb.getBasePositionAndOrientation(b, physicsClientId=c) for b in range(pb.getNumBodies(physicsClientId=c))
        ]
        assert before == after
        cup_pos = np.asarray(w.base_frame(w.bodies["cup"])[0])
        spheres = e.particles.visual_spheres()
        assert len(spheres) == e.particles.carried["water"].sum() > 0
        assert max(np.linalg.norm(np.asarray(pos) - cup_pos) for pos, _, _ in spheres) < 0.06
    finally:
        e.close()


def validate_at(tmp_path, capsys, text: str, token: str) -> tuple[int, str, str]:
    """``validate`` on a spec of ``text``: its exit code, its stderr, and ``path:line:column`` of
    the first ``token`` in the text (where the error must point)."""
    path = tmp_path / "spec.yaml"
    path.write_text(text, encoding="utf-8")
    rc = main(["validate", str(path)])
    at = text.index(token)
    return (
        rc,
        capsys.readouterr().err,
        f"{display(path)}:{text.count(chr(10), 0, at) + 1}:{at - text.rfind(chr(10), 0, at)}",
    )


def test_rest_container_must_be_a_tool_with_a_container(tmp_path, capsys):
    rc, err, where = validate_at(
        tmp_path,
        capsys,
        f"extends: {DRINKING}\nparticles:\n  water:\n    rest: {{container: wheelchair}}\n",
        "wheelchair}",
    )
    assert rc == 2
    assert err.splitlines() == [f"{where}: 'wheelchair' is not a tool with a container; tools with one: 'cup'"]


# -- Feeding with food resting in the spoon (a benchmark variant; not shipped, docs/physics.md) ----

FOOD_RESTS = Path(__file__).resolve().parents[2] / "benchmarks" / "specs" / "feeding_food_rests.yaml"


@pytest.fixture(scope="module")
def feeding_artifact(tmp_path_factory):
    return compile_task(FOOD_RESTS, "jaco", tmp_path_factory.mktemp("rest") / "feeding-jaco").out_dir


def spoon_gap_to_person(env) -> float:
    """The gap between the spoon and the person, m (inf: farther than 1 m)."""
    w, c = env.world, env.client
    person = env.particles.snap.handle(env.particles.snap.body_key("person")).id
    points = pb.getClosestPoints(w.bodies["spoon"].id, person, 1.0, -1, physicsClientId=c)
    return min((p[8] for p in points), default=math.inf)


def test_food_rides_in_the_spoon_on_the_way_and_is_simulated_near_the_person(feeding_artifact):
    """Scripted Feeding, seed 0: the food is simulated from the reset (``carry_at_reset: false``)
    and carried once it rests in the spoon on the way; an env step that
    ends with the spoon within 10 cm of the person (``simulated_near``) puts every particle back
    into the physics for the next one, and none is carried there again; the food is eaten at the
    mouth, which only simulated particles can be."""
    env = AssistiveEnv(feeding_artifact)
    try:
        rest = env.manifest.particles[0].rest
        assert (rest.near_body, rest.near_distance) == ("person", 0.1)
        policy = ScriptedPolicy(env)
        obs, _ = env.reset(seed=0)
        particles = env.particles
        assert not particles.carried["food"].any()
        carried_steps = near_steps = eaten = 0
        was_near, done = False, False
        while not done:
            carried = particles.carried["food"].copy()
            obs, _, terminated, truncated, info = env.step(policy(obs))
            done = terminated or truncated
            near = spoon_gap_to_person(env) < 0.1
            assert particles._near["food"] == near
            if was_near:  # released when this step started, simulated all through it, not carried again
                assert not particles.carried["food"].any()
            if particles.snap.events["food"].consumed:
                assert not carried.all()
            eaten += particles.snap.events["food"].consumed
            carried_steps += bool(carried.any())
            near_steps += near
            was_near = near
        assert carried_steps >= 10 and near_steps >= 10
        assert eaten >= 7 and info["task_success"]
    finally:
        env.close()


def test_simulated_near_names_a_known_body(tmp_path, capsys):
    rc, err, where = validate_at(
        tmp_path,
        capsys,
        f"extends: {FOOD_RESTS}\nparticles:\n  food:\n    rest:\n      container: spoon\n"
        "      simulated_near: {body: persn, distance_m: 0.1}\n",
        "persn",
    )
    assert rc == 2
    assert err.splitlines()[0].startswith(f"{where}: unknown body 'persn'; ")
    assert "did you mean 'person'" in err

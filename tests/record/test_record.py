"""Episode recordings: a recorded episode is the unrecorded one, and a recording replays the
episode's poses and terms without simulating."""

from __future__ import annotations

import json

import numpy as np
import pytest

from assistive_compiler.policies import make_policy
from assistive_compiler.record import RecordEpisodes, RecordingError, episode_files, load_recording, record_episode
from assistive_compiler.references import TargetPoint
from assistive_compiler.runtime.env import AssistiveEnv


@pytest.fixture(scope="module")
def recorded(env, tmp_path_factory):
    """Feeding Jaco, scripted, seed 0, recorded to a file."""
    directory = tmp_path_factory.mktemp("recordings")
    record_episode(env, make_policy("scripted", env), 0, directory, policy_name="scripted")
    return directory / "episode-0000.npz"


def test_recording_is_the_unrecorded_episode(env, recorded):
    """Recording only reads the world: every reward and term equals a plain rollout's, bit for bit."""
    rec = load_recording(recorded)
    policy = make_policy("scripted", env)
    obs, _ = env.reset(seed=0)
    rewards, terms = [], []
    for _ in range(rec.steps):
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        rewards.append(reward)
        terms.append([info["terms"][name] for name in rec.header["terms"]])
    assert truncated and rec.steps == env.manifest.sim.episode_steps == 200
    assert np.array_equal(rec.arrays["rewards"], rewards)
    assert np.array_equal(rec.arrays["terms"], terms)
    assert rec.header["success"] is bool(info["task_success"]) is True
    assert rec.header["return"] == pytest.approx(sum(rewards), abs=1e-9)


def test_replay_reproduces_poses_and_terms(env, recorded):
    """The file alone gives every step's poses: the spoon, the end effector, the mouth and the food
    read from the file equal what a fresh simulation of seed 0 shows at each step."""
    rec = load_recording(recorded)
    h = rec.header
    assert (h["format"], h["format_version"], h["seed"], h["policy"], h["complete"]) == (
        "assistive-compiler-episode",
        1,
        0,
        "scripted",
        True,
    )
    assert h["content_hash"] == env.manifest.content_hash and len(h["content_hash"]) == 64
    assert h["gym_id"] == "assistive_compiler/FeedingJaco-v1" and h["dt"] == pytest.approx(0.1)
    ee = env.manifest.robot.links["tool_mount"]
    spoon_link = next(name for name, i in env.links("spoon").items() if i == -1)
    policy = make_policy("scripted", env)
    obs, _ = env.reset(seed=0)
    for k in range(rec.steps + 1):
        if k:
            obs, _, _, _, info = env.step(policy(obs))
            assert [info["terms"][n] for n in h["terms"]] == rec.arrays["terms"][k - 1].tolist()
        pos, quat = rec.pose(k, "robot", ee)
        assert np.array_equal(pos, env.link_pose("robot", ee)[0])
        assert np.array_equal(quat, env.link_pose("robot", ee)[1])
        assert np.array_equal(rec.pose(k, "spoon", spoon_link)[0], env.base_pose("spoon")[0])
        assert np.array_equal(rec.arrays["observations"][k], obs)
        assert np.allclose(
            rec.arrays["target_pos"][k, h["targets"].index("mouth")],
            env.snap.position(env.snap.point(TargetPoint(target="mouth"))),
            atol=1e-12,
        )
        assert np.array_equal(rec.arrays["particles_active/food"][k], env.particle_state("food")[1])
    # Food was eaten in this episode, and the file saw it happen.
    active = rec.arrays["particles_active/food"]
    assert active[0].all() and active[-1].sum() < active[0].sum()


def test_recording_layout_and_header(recorded, env):
    rec = load_recording(recorded)
    h, a = rec.header, rec.arrays
    T, L = rec.steps, len(h["links"])
    assert a["link_pos"].shape == (T + 1, L, 3) and a["link_quat"].shape == (T + 1, L, 4)
    assert np.allclose(np.linalg.norm(a["link_quat"], axis=2), 1.0)
    assert a["actions"].shape == (T, 7) and a["observations"].shape == (T + 1, env.observation_space.shape[0])
    assert a["terms"].shape == (T, len(h["terms"])) and set(h["terms"]) == set(h["term_weights"])
    assert {b["name"] for b in h["bodies"]} == {b.name for b in env.manifest.bodies}
    assert sum(len(b["links"]) for b in h["bodies"]) == L
    assert h["particles"] == [
        {
            "name": "food",
            "count": 8,
            "radius": env.manifest.particles[0].radius,
            "colors": [list(c) for c in env.manifest.particles[0].colors],
        }
    ]
    assert set(h["term_categories"].values()) == {"reward", "preference"}  # Feeding's preference costs are recorded too


def test_cut_short_episode_is_written_incomplete(env, tmp_path):
    recorder = RecordEpisodes(env, tmp_path, policy="zero")
    recorder.reset(seed=3)
    for _ in range(5):
        recorder.step(np.zeros(7, dtype=np.float32))
    recorder.reset(seed=4)  # cuts episode 0 short
    files = episode_files(tmp_path)
    assert [f.name for f in files] == ["episode-0000.npz"]
    rec = load_recording(files[0])
    assert (rec.header["complete"], rec.header["steps"], rec.header["seed"]) == (False, 5, 3)
    assert not list(tmp_path.glob(".*part"))  # nothing half-written left behind


def test_not_a_recording_is_a_clear_error(tmp_path):
    bad = tmp_path / "x.npz"
    bad.write_text("hello")
    with pytest.raises(RecordingError, match=r"x.npz: not an episode recording"):
        load_recording(bad)
    np.savez(tmp_path / "y.npz", header=np.frombuffer(json.dumps({"format": "other"}).encode(), dtype=np.uint8))
    with pytest.raises(RecordingError, match=r"format 'other', expected 'assistive-compiler-episode'"):
        load_recording(tmp_path / "y.npz")


def test_record_needs_an_assistive_env(tmp_path):
    import gymnasium as gym

    with pytest.raises(TypeError, match="needs an assistive_compiler env, got CartPoleEnv"):
        RecordEpisodes(gym.make("CartPole-v1"), tmp_path)


def test_person_variant_option(env):
    """``reset(options={"person_variant": name})`` picks the variant and leaves every other draw the seed's."""
    names = [v.name for v in env.manifest.person.variants]
    _, info = env.reset(seed=1, options={"person_variant": names[-1]})
    assert info["person_variant"] == names[-1]
    with pytest.raises(ValueError, match="unknown person variant 'nobody'"):
        env.reset(seed=1, options={"person_variant": "nobody"})
    _, a = env.reset(seed=5)
    _, b = env.reset(seed=5, options={"person_variant": a["person_variant"]})
    assert a["start"] == b["start"]


def test_record_a_callable_without_policy_name(tmp_path, artifact):
    env = AssistiveEnv(artifact)
    rec = record_episode(env, lambda obs: np.zeros(7), 2, tmp_path)
    env.close()
    assert rec.header["policy"] is None and rec.header["seed"] == 2 and (tmp_path / "episode-0000.npz").is_file()


def test_run_record_writes_the_episodes_it_reports(artifact, tmp_path):
    """``run --record DIR``: one file per episode, each with the return and success ``run --json`` reports."""
    import subprocess
    import sys
    from pathlib import Path

    from conftest import FEEDING

    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "run",
            str(FEEDING),
            "--robot",
            "jaco",
            "--episodes",
            "2",
            "--seed",
            "3",
            "--out-dir",
            str(artifact),
            "--record",
            str(tmp_path / "rec"),
            "--json",
            "--quiet",
        ],
        cwd=Path(__file__).resolve().parents[2],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    files = episode_files(tmp_path / "rec")
    assert [f.name for f in files] == ["episode-0000.npz", "episode-0001.npz"]
    for f, e in zip(files, report["episodes"]):
        rec = load_recording(f)
        assert (rec.header["seed"], rec.header["success"], rec.header["policy"]) == (
            e["seed"],
            e["success"],
            "scripted",
        )
        assert rec.header["return"] == pytest.approx(e["return"], abs=1e-9)
        assert dict(zip(rec.header["terms"], rec.arrays["terms"].sum(axis=0))) == pytest.approx(e["terms"], abs=1e-9)

"""Shipped trained policies (``pretrained/``): each still succeeds on the current code as well as
when it was exported (the regression check that tells when a physics or runtime change breaks
one), each is small and says what it is, and every rollout command plays them by name —
without torch: a shipped policy runs on NumPy."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import FEEDING
from PIL import Image
from pretrained_regression import STORE, Regression, outcomes
from pretrained_regression import episodes as record_episodes

from assistive_compiler.cli import main
from assistive_compiler.policies import make_policy
from assistive_compiler.policies.pretrained import pretrained_dir, shipped_info, shipped_names
from assistive_compiler.runtime.env import AssistiveEnv

REPO = Path(__file__).resolve().parents[2]
SHIPPED = shipped_names()
#: How far a shipped policy's success on its N regression seeds may fall below the recorded figure p
#: before the test fails: Z binomial standard deviations, sqrt(p (1 - p) / N), and at least one
#: episode. Evaluation is deterministic, so on unchanged code the figure is reproduced exactly; a
#: change of physics or runtime moves single episodes, and a drop beyond the spread of 100 episodes
#: is a broken policy (at p = 85% on 100 seeds the floor is 79.1%: a fall to 79% fails).
Z = 1.645  # one-sided 95%
MAX_BYTES = 2 * 1024 * 1024
#: The paper's budget per cell (§IV), which the anchor runs train to; a PPO run stops at the end of
#: the batch that passes its budget (the paper's batch: 7,200 env steps).
PAPER_STEPS = 10_000_000 + 7_200
REGRESSION = json.loads(STORE.read_text()) if STORE.is_file() else {}


def _env(name: str, **kwargs) -> AssistiveEnv:
    from assistive_compiler.registration import cached_artifact_dir
    from assistive_compiler.training.trained.evaluate import trained_task_spec

    info = shipped_info(name)
    spec = trained_task_spec(info)
    return AssistiveEnv.from_spec(spec, robot=info["robot"], out_dir=cached_artifact_dir(spec, info["robot"]), **kwargs)


def test_the_jaco_cells_trained_here_ship():
    assert {"feeding-jaco", "scratch_itch-jaco"} <= set(SHIPPED)
    assert (REPO / "pretrained") == pretrained_dir()


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_policy_is_small_and_says_what_it_is(name):
    folder = pretrained_dir() / name
    assert sum(p.stat().st_size for p in folder.iterdir()) <= MAX_BYTES
    info = shipped_info(name)
    cell = f"{info['task']}-{info['robot']}" + ("-coop" if info["coop"] else "")
    assert name == cell or name.startswith(f"{cell}-")  # the cell's policy, or another row of it (e.g. -ppo)
    assert info["evaluation"]["episodes"] == 100 and info["evaluation"]["seed"] >= 1_000_000  # unseen seeds
    assert info["trained_steps"] <= PAPER_STEPS and info["export_max_action_difference"] < 1e-4
    env = _env(name)
    if info["coop"]:  # a robot and a human policy, each fitting its agent's spaces
        from assistive_compiler.coop.parallel import AssistiveParallelEnv
        from assistive_compiler.policies.pretrained import load_trained

        pair, _ = load_trained(f"pretrained:{name}")
        coop = AssistiveParallelEnv(env.artifact_dir)
        for agent in ("robot", "human"):
            part = pair.agent(agent)
            assert (part.obs_dim, part.action_dim) == (
                coop.observation_space(agent).shape[0],
                coop.action_space(agent).shape[0],
            )
        coop.close()
    else:
        policy = make_policy(f"pretrained:{name}", env)
        assert (policy.obs_dim, policy.action_dim) == (env.observation_space.shape[0], env.action_space.shape[0])
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_policy_still_succeeds_on_the_current_code(name):
    """Success on the regression seeds may fall by the binomial spread (allowed_drop), and the mean return by half
    the evaluation's episode-to-episode spread (which also guards policies that rarely succeed).
    Evaluation is deterministic, so the figures compared are those recorded for the same seeds.
    The first seeds are replayed; where they give the outcomes recorded for the current code
    (tests/pretrained_regression.py), so do the others, and those are taken from the record."""
    info = shipped_info(name)
    reg = info["regression"]
    evaluation = info["evaluation"]
    assert evaluation["seed"] == reg["seed"]  # the regression seeds are the evaluation's first ones
    regression = Regression(name)
    episodes, replayed = regression.episodes, regression.replayed
    recorded = REGRESSION.get(name, {"returns": [], "successes": []})
    try:
        runs = regression.play(0, replayed)
        as_recorded = {k: v[:replayed] for k, v in recorded.items()}
        if len(recorded["returns"]) == episodes and outcomes(runs) == as_recorded:  # the code plays as recorded
            runs += record_episodes({k: v[replayed:] for k, v in recorded.items()})
        else:  # a change since the record (or none): replay every regression seed
            runs += regression.play(replayed, episodes - replayed)
    finally:
        regression.close()
    recorded_success = float(np.mean(evaluation["successes"][:episodes]))
    recorded_return = float(np.mean(evaluation["returns"][:episodes]))
    seeds = f"seeds {reg['seed']}..{reg['seed'] + episodes - 1}"
    success = float(np.mean([r["success"] for r in runs]))
    floor = recorded_success - allowed_drop(recorded_success, episodes)
    assert success >= floor - 1e-9, (
        f"pretrained:{name} succeeds on {success:.0%} of {seeds}, evaluated at {recorded_success:.0%} (floor "
        f"{floor:.1%}): a physics or runtime change broke it; retrain it, or evaluate it again if the change is meant"
    )
    mean_return = float(np.mean([r["return"] for r in runs]))
    floor = recorded_return - 0.5 * evaluation["std_return"]
    assert mean_return >= floor, (
        f"pretrained:{name} returns {mean_return:.1f} on {seeds}, exported at "
        f"{recorded_return:.1f} (floor {floor:.1f}): a physics or runtime change broke it"
    )


#: Shipped policies whose figures are still those measured on an older compile of their task, and
#: why: Dressing's cloth makes an episode 20-40 s here, so its 100 evaluation episodes take about
#: 50 minutes a policy, which the sitting that re-evaluated the others (2026-12-07) did not have.
#: The test fails when one of these is measured again (take it off the list) as when another goes stale.
AWAITING_REEVALUATION = {"dressing-jaco", "dressing-jaco-coop", "dressing-jaco-coop-sac"}


def test_every_shipped_figure_was_measured_on_the_task_the_code_compiles_now():
    """A change that alters a shipped task's compile re-evaluates its policies (``assistive-compiler
    results --reevaluate``), so that the shipped figures are the current code's."""
    from assistive_compiler.training.trained.reevaluate import stale_figures

    stale = {s.name: str(s) for s in stale_figures(SHIPPED)}
    assert set(stale) == AWAITING_REEVALUATION & set(SHIPPED), (
        "shipped figures measured on another compile of their task than the current code's: "
        + "; ".join(v for k, v in stale.items() if k not in AWAITING_REEVALUATION)
        + " (run `assistive-compiler results --reevaluate`, then `python -m tests.pretrained_regression --write --from-evaluation`)"
        + "; re-evaluated since, off the list: "
        + ", ".join(sorted(AWAITING_REEVALUATION & set(SHIPPED) - set(stale)))
    )


def allowed_drop(success_rate: float, episodes: int) -> float:
    """How far success on ``episodes`` regression seeds may fall below ``success_rate`` (see Z)."""
    return max(Z * float(np.sqrt(success_rate * (1.0 - success_rate) / episodes)), 1.0 / episodes)


def test_the_regression_bound_fails_on_a_drop_like_arm_manipulations():
    """The bound the regression check holds a shipped policy to, on the 100 seeds of its evaluation:
    Arm Manipulation's 85% falling to 78% (found by hand once; the fixed 0.2 on 10 seeds let it
    pass) fails, one or two episodes lost pass, and a policy that never succeeded may lose nothing."""
    assert 0.85 - allowed_drop(0.85, 100) == pytest.approx(0.7913, abs=1e-4)
    assert 0.78 < 0.85 - allowed_drop(0.85, 100) < 0.83
    assert allowed_drop(0.0, 100) == 0.01 and allowed_drop(0.25, 4) == pytest.approx(0.3561, abs=1e-4)


def test_unknown_or_misfit_pretrained_policies_are_clear_errors(capsys):
    assert (
        main(["run", str(FEEDING), "--robot", "jaco", "--policy", "pretrained:feeding-jacco", "--episodes", "1"]) == 2
    )
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: --policy pretrained:feeding-jacco: no shipped policy of that name; shipped: ")
    assert err.endswith("(did you mean 'feeding-jaco'?)")
    assert main(["run", str(FEEDING), "--robot", "pr2", "--policy", "pretrained:feeding-jaco", "--episodes", "1"]) == 2
    assert (
        capsys.readouterr()
        .err.strip()
        .endswith(
            "error: --policy pretrained:feeding-jaco: trained for feeding with jaco, but the env is feeding with pr2"
        )
    )


@pytest.mark.slow
def test_every_rollout_command_plays_a_shipped_policy(capsys, tmp_path, monkeypatch):
    """run, render, compare, evaluate, the viewer's episode and collect all play
    pretrained:feeding-jaco, and agree on its episodes."""
    name, seed = "feeding-jaco", 1_000_000
    source = f"pretrained:{name}"
    assert (
        main(
            [
                "run",
                str(FEEDING),
                "--robot",
                "jaco",
                "--policy",
                source,
                "--episodes",
                "2",
                "--seed",
                str(seed),
                "--json",
                "--quiet",
            ]
        )
        == 0
    )
    report = json.loads(capsys.readouterr().out)
    returns = [round(e["return"], 3) for e in report["episodes"]]
    # The shipped policy, playing as it did at export: the same outcome on each seed (its return to
    # the last digit only until a physics change; test_shipped_policy_still_succeeds... guards those).
    evaluation = shipped_info(name)["evaluation"]
    assert report["policy"] == source and [e["success"] for e in report["episodes"]] == evaluation["successes"][:2]
    assert returns == pytest.approx(evaluation["returns"][:2], rel=0.1)

    assert main(["evaluate", "--policy", source, "--episodes", "2", "--seed", str(seed), "--json"]) == 0
    assert [round(e["return"], 3) for e in json.loads(capsys.readouterr().out)["per_episode"]] == returns

    png = tmp_path / "feeding.png"
    assert (
        main(["render", str(FEEDING), "--robot", "jaco", "--policy", source, "--seed", str(seed), "--out", str(png)])
        == 0
    )
    assert f"return {returns[0]:.1f}" in capsys.readouterr().out and Image.open(png).size[0] > 500

    assert (
        main(
            [
                "compare",
                str(FEEDING),
                "--robots",
                "jaco",
                "--policy",
                "pretrained",
                "--episodes",
                "2",
                "--seed",
                str(seed),
                "--json",
            ]
        )
        == 0
    )
    row = json.loads(capsys.readouterr().out)[0]
    assert row["return"] == round(float(np.mean(returns)), 1)

    from assistive_compiler.viewer import episode_for_view

    _, recording, _ = episode_for_view(str(FEEDING), "jaco", policy=source, seed=seed)
    assert round(float(recording.arrays["rewards"].sum()), 3) == pytest.approx(returns[0], abs=1e-3)

    pytest.importorskip("minari", reason='needs the "datasets" extra')
    root = tmp_path / "minari"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "collect",
            str(FEEDING),
            "--robot",
            "jaco",
            "--policy",
            source,
            "--episodes",
            "1",
            "--seed",
            str(seed),
            "--out",
            "assistive_compiler/feeding-jaco/sac-v0",
            "--root",
            str(root),
            "--quiet",
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    import minari

    monkeypatch.setenv("MINARI_DATASETS_PATH", str(root))
    dataset = minari.load_dataset("assistive_compiler/feeding-jaco/sac-v0")
    episode = next(dataset.iterate_episodes())
    assert round(float(episode.rewards.sum()), 3) == pytest.approx(returns[0], abs=1e-3)
    assert dataset.storage.metadata["assistive_compiler"]["policy"] == source


def test_a_shipped_policy_runs_without_torch(tmp_path):
    code = (
        "import sys; sys.modules['torch'] = None; sys.modules['stable_baselines3'] = None\n"
        "from assistive_compiler.cli import main\n"
        f"sys.exit(main(['run', {str(FEEDING)!r}, '--robot', 'jaco', '--policy', 'pretrained:feeding-jaco', "
        "'--episodes', '1', '--quiet']))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=REPO)
    assert proc.returncode == 0, proc.stderr
    assert "policy=pretrained:feeding-jaco" in proc.stdout


def test_a_policy_exported_without_its_log_std_acts_on_its_mean_and_refuses_to_sample():
    """Policies exported before exports kept their log-std have a mean only: they still act, and
    asking them for their Gaussian or for sampled actions says why there is none."""
    from assistive_compiler.policies.mlp import MLPPolicy

    older = MLPPolicy.load(pretrained_dir() / "feeding-jaco")
    assert not older.samples
    obs = np.zeros(older.obs_dim, dtype=np.float32)
    assert older(obs).shape == (older.action_dim,)
    expected = "this policy was exported without its log-std (by an earlier version): it has a mean only"
    with pytest.raises(ValueError) as asked_for_gaussian:
        older.mean_and_std(obs)
    with pytest.raises(ValueError) as asked_to_sample:
        older.sampling(seed=0)
    assert str(asked_for_gaussian.value) == str(asked_to_sample.value) == expected

"""Training configs (specs/training/*.yaml): shipped ones validate and match their JSON Schema;
mistakes are located; the learning commands' usage errors are clear; nothing heavy is imported
by the package or the CLI parser."""

from __future__ import annotations

from pathlib import Path

import jsonschema
import pytest
from helpers import at

from assistive_compiler.cli import main
from assistive_compiler.errors import SpecError
from assistive_compiler.training.config import TrainingConfig, load_training_config, training_schema

REPO = Path(__file__).resolve().parents[2]
SHIPPED = sorted((REPO / "specs" / "training").glob("*.yaml"))
REACH = REPO / "specs" / "examples" / "reach.yaml"


def _problems(path, text: str) -> list[str]:
    """The located problems that loading ``text``, written to ``path``, reports."""
    path.write_text(text)
    with pytest.raises(SpecError) as err:
        load_training_config(path)
    return [str(p) for p in err.value.problems]


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_configs_validate_and_match_the_schema(path):
    import yaml

    config = load_training_config(path)
    assert config.algorithm in ("ppo", "sac") and getattr(config, config.algorithm) is not None
    jsonschema.validate(yaml.safe_load(path.read_text()), training_schema())


def test_paper_config_is_the_papers_setup():
    """Paper §IV: 2×64 tanh, 36 actors × 200-step rollouts (7,200 per update), 10 epochs, 10M steps."""
    c = load_training_config(REPO / "specs" / "training" / "ppo_paper.yaml")
    assert (c.network.hidden, c.network.activation) == ([64, 64], "tanh")
    assert (c.envs, c.ppo.rollout_steps, c.batch_size, c.ppo.epochs, c.total_steps) == (36, 200, 7200, 10, 10_000_000)
    ref = load_training_config(REPO / "specs" / "training" / "ppo_rllib_reference.yaml")
    assert (ref.batch_size, ref.ppo.epochs, ref.ppo.minibatch_size, ref.ppo.gae_lambda, ref.network.hidden) == (
        19200,
        50,
        128,
        0.95,
        [100, 100],
    )


def test_mistakes_are_located(tmp_path):
    text = (
        "algorithm: ppo\n"
        "network: {hidden: [64, 0]}\n"
        "ppo: {rollout_steps: 10, minibatch_size: 8, epochs: ten, learning_rat: 0.1}\n"
        "total_step: 100\n"
        "checkpoint_every_steps: 50\n"
    )
    path = tmp_path / "bad.yaml"
    messages = _problems(path, text)
    name = str(path)
    assert f"{name}:{at(text, '[64, 0]')}: network.hidden: every layer width must be ≥ 1, got [64, 0]" in messages
    assert (
        f"{name}:{at(text, 'ten')}: ppo.epochs: must be a valid integer, unable to parse string as an integer, got 'ten'"
        in messages
    )
    assert any(
        m.startswith(f"{name}:{at(text, 'learning_rat')}: unknown key 'learning_rat' in ppo")
        and "(did you mean 'learning_rate'?)" in m
        for m in messages
    )
    assert any(
        m.startswith(f"{name}:{at(text, 'total_step')}: unknown key 'total_step'")
        and "(did you mean 'total_steps'?)" in m
        for m in messages
    )
    assert f"{name}:1:1: missing required key 'total_steps' in the spec" in messages


def test_minibatch_larger_than_the_batch_is_located(tmp_path):
    text = "algorithm: ppo\nppo: {rollout_steps: 10, minibatch_size: 64, epochs: 1}\nenvs: 2\ntotal_steps: 100\ncheckpoint_every_steps: 50\n"
    path = tmp_path / "batch.yaml"
    assert _problems(path, text) == [
        f"{path}:{at(text, '64')}: ppo.minibatch_size: minibatch_size 64 is larger than the batch rollout_steps × envs = 10 × 2 = 20"
    ]


def test_sac_recipe_is_standard_sac_on_one_env():
    """The recipe (sac_laptop): SB3's standard SAC settings, one env process, one update per env step."""
    c = load_training_config(REPO / "specs" / "training" / "sac_laptop.yaml")
    assert (c.algorithm, c.ppo, c.envs, c.network.hidden, c.network.activation) == ("sac", None, 1, [256, 256], "relu")
    s = c.sac
    assert (s.learning_rate, s.batch_size, s.tau, s.gamma, s.ent_coef, s.target_entropy) == (
        3e-4,
        256,
        0.005,
        0.99,
        "auto",
        "auto",
    )
    assert (s.train_freq, s.gradient_steps, c.batch_size, c.gamma, c.total_steps) == (1, 1, 1, 0.99, 1_000_000)


def test_algorithm_and_its_section_must_agree(tmp_path):
    text = (
        "algorithm: sac\nppo: {rollout_steps: 10, minibatch_size: 8, epochs: 1}\n"
        "sac: {ent_coef: -0.1, gradient_stepz: 2}\ntotal_steps: 100\ncheckpoint_every_steps: 50\n"
    )
    path = tmp_path / "mixed.yaml"
    messages = _problems(path, text)
    assert any(
        m.startswith(f"{path}:{at(text, 'gradient_stepz')}: unknown key 'gradient_stepz' in sac")
        and "(did you mean 'gradient_steps'?)" in m
        for m in messages
    ), messages
    text = "algorithm: sac\nppo: {rollout_steps: 10, minibatch_size: 8, epochs: 1}\nsac: {ent_coef: -0.1}\ntotal_steps: 100\ncheckpoint_every_steps: 50\n"
    assert _problems(path, text) == [
        f"{path}:{at(text, '-0.1')}: sac.ent_coef: the entropy temperature must be > 0 (or 'auto'), got -0.1"
    ]
    text = (
        "algorithm: sac\nsac: {ent_coef: 0.2, initial_ent_coef: 0.01}\ntotal_steps: 100\ncheckpoint_every_steps: 50\n"
    )
    assert _problems(path, text) == [
        f"{path}:{at(text, '0.01')}: sac.initial_ent_coef: the temperature α is fixed at ent_coef 0.2; "
        "a starting value is for ent_coef: auto only"
    ]
    text = "algorithm: sac\nppo: {rollout_steps: 10, minibatch_size: 8, epochs: 1}\nsac: {}\ntotal_steps: 100\ncheckpoint_every_steps: 50\n"
    assert _problems(path, text) == [
        f"{path}:{at(text, '{rollout_steps')}: ppo: a 'ppo:' section configures algorithm 'ppo', but algorithm is 'sac'; "
        "remove it or set algorithm: ppo"
    ]
    text = "algorithm: sac\ntotal_steps: 100\ncheckpoint_every_steps: 50\n"
    assert _problems(path, text) == [f"{path}:1:1: sac: algorithm 'sac' needs its settings in a 'sac:' section"]


def test_overrides_are_validated():
    base = load_training_config(REPO / "specs" / "training" / "ppo_quick.yaml")
    assert base.with_overrides(steps=500, seed=3, envs=1).model_dump()["total_steps"] == 500
    from assistive_compiler.errors import UsageError

    with pytest.raises(UsageError):
        base.with_overrides(envs=0)
    assert isinstance(base, TrainingConfig)


def run_cli(args, capsys) -> tuple[int, str]:
    code = main(args)
    return code, capsys.readouterr().err


def test_unknown_engine_is_refused_with_a_suggestion(capsys):
    code, err = run_cli(["train", str(REACH), "--config", "ppo_quick", "--engine", "sbx"], capsys)
    assert code == 2
    assert (
        err.strip()
        == "error: --engine: unknown engine 'sbx'; expected one of 'auto', 'rllib', 'sb3' (did you mean 'sb3'?)"
    )


def test_coop_on_a_task_without_human_policy_joints_is_refused(capsys, tmp_path):
    code, err = run_cli(
        ["train", str(REACH), "--config", "ppo_quick", "--coop", "--out", str(tmp_path / "run")], capsys
    )
    assert code == 2 and not (tmp_path / "run").exists()
    from assistive_compiler.paths import display

    text, name = REACH.read_text(), display(REACH)
    lines = err.strip().splitlines()
    assert lines[0] == (
        f"{name}:{at(text, 'variants:')}: person.control.policy_joints: the person controls no joints, so it cannot be "
        "a co-optimisation agent; list the joint groups a human policy moves, e.g. [person.head] or [person.right_arm]"
    )
    assert lines[1].startswith(f"{name}:{at(text, 'robot:', 2)}: observations.human: the person observes nothing")


def test_evaluate_on_a_directory_that_is_not_a_run(capsys, tmp_path):
    code, err = run_cli(["evaluate", str(tmp_path)], capsys)
    assert code == 2
    assert err.strip() == f"error: {tmp_path}: not a run directory (no run.json); `assistive-compiler train` writes one"


def test_the_reach_example_is_not_a_registered_id():
    from assistive_compiler.gym_ids import shipped_ids

    assert not [i for i in shipped_ids() if "Reach" in i]


def test_a_cloned_target_entropy_needs_a_clone_and_a_learned_temperature(tmp_path):
    path = tmp_path / "cloned.yaml"
    for sac, extra, expected in (
        (
            "{target_entropy: cloned}",
            "",
            "'cloned' is the entropy of the policy cloned from demonstrations; add a demonstrations block with "
            "clone_epochs > 0, or give a number or 'auto'",
        ),
        (
            "{target_entropy: cloned, ent_coef: 0.1}",
            "demonstrations: {}\n",
            "'cloned' is what a learned temperature tunes toward; set ent_coef: auto",
        ),
    ):
        text = f"algorithm: sac\nsac: {sac}\ntotal_steps: 100\ncheckpoint_every_steps: 50\n{extra}"
        assert _problems(path, text) == [f"{path}:{at(text, 'cloned')}: sac.target_entropy: {expected}"]


def test_sac_demos_is_the_recipe_started_from_demonstrations():
    """sac_demos: sac_laptop's SAC without the phase of random actions (the demonstrations fill the
    buffer), a small starting temperature tuned to the clone's entropy, layer-normalised and
    conservative critics, the actor held and then anchored to the demonstrations: the settings
    of the Drinking run that improved on its clone (docs/results.md, tenth sitting), with the
    dataset left to --demonstrations."""
    demos = load_training_config(REPO / "specs" / "training" / "sac_demos.yaml")
    recipe = load_training_config(REPO / "specs" / "training" / "sac_laptop.yaml")
    assert demos.sac.learning_starts == 0 and recipe.sac.learning_starts == 5000
    # the temperature starts small: the cloned policy is narrow, and α = 1 widens it into noise
    assert demos.sac.initial_ent_coef == 0.01 and recipe.sac.initial_ent_coef == 1.0
    assert demos.sac.target_entropy == "cloned" and demos.sac.critic_layer_norm
    assert demos.sac.conservative_weight == 2.0 and recipe.sac.conservative_weight == 0.0
    changed = {"learning_starts", "initial_ent_coef", "target_entropy", "critic_layer_norm", "conservative_weight"}
    assert demos.sac.model_copy(update={k: getattr(recipe.sac, k) for k in changed}) == recipe.sac
    assert (demos.network, demos.total_steps, demos.envs) == (recipe.network, recipe.total_steps, recipe.envs)
    d = demos.demonstrations
    assert d is not None and d.dataset is None and d.replay and d.critic_warmup_steps == 5000
    assert (d.clone_weight, d.hold_actor_steps) == (2.5, 10_000)
    assert demos.with_overrides(demonstrations="a/b-v0").demonstrations == d.model_copy(update={"dataset": "a/b-v0"})


def test_sac_low_entropy_is_the_recipe_with_less_noise_to_hide_behind():
    """sac_low_entropy: sac_laptop with the target entropy three nats per Jaco joint lower (−21),
    nothing else changed, so its comparison with sac_laptop on Itch Scratching is one change."""
    low = load_training_config(REPO / "specs" / "training" / "sac_low_entropy.yaml")
    recipe = load_training_config(REPO / "specs" / "training" / "sac_laptop.yaml")
    assert low.sac.target_entropy == -21.0 and recipe.sac.target_entropy == "auto"
    assert low.sac.model_copy(update={"target_entropy": "auto"}) == recipe.sac
    assert low.model_copy(update={"sac": recipe.sac, "description": recipe.description}) == recipe

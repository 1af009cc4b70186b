"""Training configs are specs too: validated YAML (``specs/training/*.yaml``) with located errors.

A :class:`TrainingConfig` says *how* to learn a task's policy — algorithm (the paper's on-policy
PPO, or the off-policy SAC that learns from far fewer env steps), network, the algorithm's own
settings, how many steps and env processes, the seed and how often to checkpoint. The same config
drives Stable-Baselines3 (single agent, one machine) and Ray RLlib (co-optimisation, clusters);
:mod:`.engines.sb3` and :mod:`.engines.rllib` translate it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from ..errors import SpecError, UsageError
from ..paths import display
from ..run_dir import RunInfo
from ..yamlsrc import load_located


class Strict(BaseModel):
    """Unknown keys are errors, NaN and infinities are refused."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)


class Network(Strict):
    """The policy and value networks: separate MLPs of the same shape."""

    hidden: list[int] = Field(
        [64, 64],
        min_length=1,
        max_length=8,
        description="Hidden layer widths (the paper: [64, 64]; the reference v1.0 RLlib config: [100, 100]).",
    )
    activation: Literal["tanh", "relu"] = Field("tanh", description="Hidden-layer activation (the paper: tanh).")

    @model_validator(mode="after")
    def _positive(self) -> Network:
        if any(w < 1 for w in self.hidden):
            raise ValueError(f"@hidden: every layer width must be ≥ 1, got {self.hidden}")
        return self


class PPO(Strict):
    """Proximal policy optimisation (Schulman et al. 2017) settings."""

    rollout_steps: int = Field(
        ge=1,
        le=1_000_000,
        description="Env steps each env process collects per update; the batch is rollout_steps × envs (the paper: 200 × 36 = 7,200).",
    )
    minibatch_size: int = Field(ge=1, description="Samples per gradient step (the reference v1.0 RLlib config: 128).")
    epochs: int = Field(
        ge=1, le=1000, description="Passes over each batch (the paper: 10; the reference v1.0 RLlib config: 50)."
    )
    gamma: float = Field(0.99, gt=0, le=1, description="Discount factor γ per env step.")
    gae_lambda: float = Field(0.95, ge=0, le=1, description="GAE λ (the reference: 0.95).")
    learning_rate: float = Field(3e-4, gt=0, le=1, description="Adam learning rate.")
    clip_range: float = Field(0.2, gt=0, le=1, description="PPO's probability-ratio clip ε.")
    entropy_coef: float = Field(0.0, ge=0, le=1, description="Weight of the entropy bonus.")
    value_coef: float = Field(0.5, ge=0, le=10, description="Weight of the value loss.")
    max_grad_norm: float = Field(0.5, gt=0, le=100, description="Gradient norm clip.")
    normalize_observations: bool = Field(
        True,
        description="Running mean/std normalisation of observations (pytorch-a2c-ppo-acktr, the paper's trainer, does this).",
    )
    normalize_rewards: bool = Field(
        True, description="Scale rewards by a running std of the discounted return (as that trainer)."
    )


class SAC(Strict):
    """Soft actor-critic (Haarnoja et al. 2018) settings: off-policy, a replay buffer, twin Q
    critics and an entropy temperature tuned to a target entropy."""

    learning_rate: float = Field(
        3e-4,
        gt=0,
        le=1,
        description="Adam learning rate of the critics and the temperature, and of the actor unless "
        "actor_learning_rate gives it its own.",
    )
    actor_learning_rate: float | None = Field(
        None,
        gt=0,
        le=1,
        description="Adam learning rate of the actor alone (none: learning_rate). A smaller one keeps the actor "
        "from running ahead of critics that are still learning its returns.",
    )
    buffer_size: int = Field(
        1_000_000, ge=1, description="Transitions the replay buffer holds (the oldest are overwritten)."
    )
    learning_starts: int = Field(
        5_000,
        ge=0,
        description="Env steps of uniformly random actions before the first update (fills the buffer with varied data).",
    )
    batch_size: int = Field(256, ge=1, description="Transitions per gradient step, sampled uniformly from the buffer.")
    tau: float = Field(0.005, gt=0, le=1, description="Polyak factor of the target critics' soft update.")
    gamma: float = Field(0.99, gt=0, le=1, description="Discount factor γ per env step.")
    train_freq: int = Field(1, ge=1, description="Env steps (per env process) between updates.")
    gradient_steps: int = Field(
        1,
        ge=1,
        le=1000,
        description="Gradient steps per update; updates per env step = gradient_steps / (train_freq × envs).",
    )
    ent_coef: float | Literal["auto"] = Field(
        "auto", description="Entropy temperature α: a number, or 'auto' to learn it toward target_entropy."
    )
    initial_ent_coef: float = Field(
        1.0,
        gt=0,
        le=10,
        description="The temperature α that ent_coef 'auto' starts from (SB3's and RLlib's default 1.0). A policy "
        "that starts narrow (cloned from demonstrations: log π ≫ 0) needs a small one, or the entropy term of the "
        "soft targets outweighs the rewards.",
    )
    target_entropy: float | Literal["auto", "cloned"] = Field(
        "auto",
        description="Target policy entropy (nats) with ent_coef 'auto'; 'auto' is −(action dimensions); 'cloned' "
        "(a run started from demonstrations) is the cloned policy's own entropy on the demonstrations, so SAC "
        "explores as widely as the clone misses them instead of widening it to −(action dimensions).",
    )
    critic_layer_norm: bool = Field(
        False,
        description="Layer-normalise every hidden layer of the twin critics (RLPD, Ball et al. 2023): their "
        "values stay bounded where the data are thin, as in a run started from demonstrations (SB3 engine only).",
    )
    conservative_weight: float = Field(
        0.0,
        ge=0,
        le=100,
        description="Weight of CQL's regulariser (Kumar et al. 2020) in every critic update, the critic warm-up "
        "on demonstrations included: the critics value actions the replay buffer did not take (uniform and "
        "policy samples) below the ones it did, so the actor is not led off into actions nobody tried. In Q's units "
        "(CQL's MuJoCo runs: 5). 0: SAC's own critic loss (SB3 engine only).",
    )
    actor_average_tau: float = Field(
        0.0,
        ge=0,
        le=1,
        description="Act, evaluate and export with an exponential moving average of the actor's weights "
        "instead of the actor itself (policy weight averaging, Nikishin et al. 2018): after each actor update "
        "average ← (1 − τ)·average + τ·actor, so it follows the actor over about 1/τ updates and a checkpoint "
        "is not one snapshot of a policy that swings between updates. Training still explores and learns with "
        "the actor itself. 0: off (SB3 engine only).",
    )

    library: Literal["sb3", "sbx"] = Field(
        "sb3",
        description="Which implementation learns: 'sb3' (Stable-Baselines3, PyTorch: every option here) or 'sbx' "
        "(SBX, the Stable-Baselines3 team's JAX port, package sbx-rl: the same SAC with jit-compiled updates, about "
        "twice as many updates per core-second for small networks; the same checkpoints, callbacks, resume and "
        "export, but not critic_layer_norm, conservative_weight, actor_average_tau, actor_learning_rate, "
        "demonstrations or co-optimisation). SB3 engine only.",
    )

    @model_validator(mode="after")
    def _sbx_options(self) -> SAC:
        if self.library != "sbx":
            return self
        unsupported = [
            name
            for name, default in (
                ("critic_layer_norm", False),
                ("conservative_weight", 0.0),
                ("actor_average_tau", 0.0),
                ("actor_learning_rate", None),
            )
            if getattr(self, name) != default
        ]
        if unsupported:
            raise ValueError(
                f"@library: {', '.join(unsupported)} {'is' if len(unsupported) == 1 else 'are'} built on SB3's "
                "PyTorch SAC; library 'sbx' does not have it: set library: sb3, or leave "
                f"{'it' if len(unsupported) == 1 else 'them'} at the default"
            )
        return self

    @model_validator(mode="after")
    def _positive_temperature(self) -> SAC:
        if not isinstance(self.ent_coef, str) and self.ent_coef <= 0:
            raise ValueError(f"@ent_coef: the entropy temperature must be > 0 (or 'auto'), got {self.ent_coef}")
        if not isinstance(self.ent_coef, str) and self.initial_ent_coef != 1.0:
            raise ValueError(
                f"@initial_ent_coef: the temperature α is fixed at ent_coef {self.ent_coef:g}; a starting value "
                "is for ent_coef: auto only"
            )
        return self


class Demonstrations(Strict):
    """Start a new run from demonstrations: a Minari dataset that ``collect`` wrote on the same
    compiled task (:mod:`.learners.demonstrations`). Before the first env step, the actor is fitted to the
    successful episodes' actions (behaviour cloning), every demonstrated transition goes into the
    replay buffer and the critics warm up on them; optionally a cloning term stays in the actor's
    loss while SAC learns. Results from such a run are labelled as starting from demonstrations."""

    dataset: str | None = Field(
        None,
        min_length=1,
        description="Minari dataset id, e.g. assistive_compiler/drinking-jaco/scripted-v0 (None: the one "
        "train --demonstrations names; a run cannot start without one).",
    )
    root: str | None = Field(
        None, description="Datasets directory (None: $MINARI_DATASETS_PATH, else Minari's ~/.minari/datasets)."
    )
    clone_epochs: int = Field(
        50, ge=0, le=10_000, description="Passes of behaviour cloning over the successful episodes' steps (0: none)."
    )
    clone_batch_size: int = Field(256, ge=1, description="Demonstrated steps per behaviour-cloning gradient step.")
    clone_learning_rate: float = Field(1e-3, gt=0, le=1, description="Adam learning rate of behaviour cloning.")
    replay: bool = Field(
        True, description="Put every demonstrated transition (failed episodes too) into the replay buffer first."
    )
    critic_warmup_steps: int = Field(
        5_000,
        ge=0,
        le=1_000_000,
        description="Gradient steps of the critics alone on the demonstrations (the cloned actor held) before SAC "
        "starts, so its first actor updates follow critics that have seen the demonstrated returns (0: none).",
    )

    clone_weight: float = Field(
        0.0,
        ge=0,
        le=100,
        description="Weight of a behaviour-cloning term kept in SAC's actor loss while it learns: at each actor "
        "update, clone_weight × the mean |Q| of a batch of demonstrated (state, action) pairs × the cloning loss on "
        "them (the deterministic action's mean squared miss, and σ's likelihood of it; TD3+BC's scaling: the term's "
        "pull does not depend on how large the task's returns are). It keeps the actor near the demonstrations "
        "where its critics know little. 0: after the start, SAC's own actor loss alone.",
    )

    hold_actor_steps: int = Field(
        0,
        ge=0,
        le=1_000_000,
        description="SAC's first gradient steps during which the actor is not updated (the critics and the "
        "temperature are), so the critics learn the cloned policy's own returns online before the actor follows "
        "them (0: the actor updates from the first step).",
    )

    @property
    def steers_actor_updates(self) -> bool:
        """Whether SAC's actor updates use the demonstrations after the start (a kept cloning term or
        a hold), so a resumed run reads the dataset again."""
        return self.clone_weight > 0 or self.hold_actor_steps > 0

    @model_validator(mode="after")
    def _warmup_needs_replay(self) -> Demonstrations:
        if self.critic_warmup_steps and not self.replay:
            raise ValueError(
                "@critic_warmup_steps: the critics warm up on the demonstrations in the replay buffer; "
                "set replay: true or critic_warmup_steps: 0"
            )
        return self


ALGORITHM_SECTIONS = {"ppo": "PPO", "sac": "SAC"}


class TrainingConfig(Strict):
    """How to train a policy for one task and robot."""

    algorithm: Literal["ppo", "sac"] = Field(
        description="The learning algorithm: 'ppo' (the paper's) or 'sac' (off-policy: far fewer env steps per success). "
        "Its settings go in the section of the same name."
    )
    description: str = Field("", description="What this config is for, in a sentence.")
    network: Network = Field(
        default_factory=Network, description="Network shape: PPO's policy and value MLPs, SAC's actor and each critic."
    )
    ppo: PPO | None = Field(None, description="PPO settings (algorithm: ppo).")
    sac: SAC | None = Field(None, description="SAC settings (algorithm: sac).")
    total_steps: int = Field(
        ge=1, description="Env steps to train for, over all env processes (the paper: 10,000,000)."
    )
    envs: int = Field(1, ge=1, le=1024, description="Envs collecting experience in parallel (the paper: 36).")
    vec_env: Literal["processes", "in_process"] = Field(
        "processes",
        description="Where the envs step: 'processes' runs each env in a process of its own (SB3's SubprocVecEnv: "
        "one core per env; one env alone runs in the trainer's process); 'in_process' steps all of them in turn in "
        "the trainer's process (SB3's DummyVecEnv: one core, no inter-process traffic, and the policy acts for "
        "all envs in one batched forward pass), so the paper's 36 envs train on one core. SB3 engine only; RLlib "
        "runs one env per env runner.",
    )
    seed: int = Field(0, ge=0, description="Seed of the policy's initialisation, the envs and the sampling.")
    checkpoint_every_steps: int = Field(
        ge=1, description="Env steps between checkpoints (a checkpoint is also written at the end and on Ctrl-C)."
    )
    eval_episodes: int = Field(100, ge=1, description="Episodes `evaluate` runs by default (the paper: 100 rollouts).")
    demonstrations: Demonstrations | None = Field(
        None,
        description="Start from a demonstration dataset (train --demonstrations DATASET); SAC only. None: pure RL.",
    )

    @model_validator(mode="after")
    def _one_algorithm_section(self) -> TrainingConfig:
        for name in ALGORITHM_SECTIONS:
            given = getattr(self, name) is not None
            if name == self.algorithm and not given:
                raise ValueError(f"@{name}: algorithm '{name}' needs its settings in a '{name}:' section")
            if name != self.algorithm and given:
                raise ValueError(
                    f"@{name}: a '{name}:' section configures algorithm '{name}', but algorithm is "
                    f"'{self.algorithm}'; remove it or set algorithm: {name}"
                )
        return self

    @model_validator(mode="after")
    def _batch(self) -> TrainingConfig:
        if self.ppo is None:
            return self
        batch = self.ppo.rollout_steps * self.envs
        if self.ppo.minibatch_size > batch:
            raise ValueError(
                f"@ppo.minibatch_size: minibatch_size {self.ppo.minibatch_size} is larger than the batch "
                f"rollout_steps × envs = {self.ppo.rollout_steps} × {self.envs} = {batch}"
            )
        return self

    @model_validator(mode="after")
    def _cloned_entropy_needs_cloning(self) -> TrainingConfig:
        if self.sac is not None and self.sac.target_entropy == "cloned":
            if self.demonstrations is None or self.demonstrations.clone_epochs == 0:
                raise ValueError(
                    "@sac.target_entropy: 'cloned' is the entropy of the policy cloned from demonstrations; "
                    "add a demonstrations block with clone_epochs > 0, or give a number or 'auto'"
                )
            if self.sac.ent_coef != "auto":
                raise ValueError(
                    "@sac.target_entropy: 'cloned' is what a learned temperature tunes toward; set ent_coef: auto"
                )
        return self

    @model_validator(mode="after")
    def _demonstrations_need_sac(self) -> TrainingConfig:
        if self.demonstrations is not None and self.algorithm != "sac":
            raise ValueError(
                f"@demonstrations: starting from demonstrations fits SAC's actor and fills its replay buffer; "
                f"algorithm is '{self.algorithm}' (use a SAC config, e.g. sac_laptop)"
            )
        if self.demonstrations is not None and self.sac is not None and self.sac.library == "sbx":
            raise ValueError(
                "@demonstrations: starting from demonstrations clones into SB3's PyTorch actor; "
                "sac.library is 'sbx' (set library: sb3)"
            )
        if self.demonstrations is not None and self.envs != 1:
            raise ValueError(
                f"@demonstrations: starting from demonstrations needs envs: 1 (the replay buffer is filled as one "
                f"env process's), got envs: {self.envs}"
            )
        return self

    @property
    def batch_size(self) -> int:
        """Env steps per update, over all env processes (PPO: rollout_steps × envs; SAC: train_freq × envs)."""
        if self.ppo is not None:
            return self.ppo.rollout_steps * self.envs
        return self.sac.train_freq * self.envs

    @property
    def library(self) -> str:
        """The implementation that learns on the SB3 engine: ``sb3`` (PyTorch) or ``sbx`` (JAX; SAC only)."""
        return self.sac.library if self.sac is not None else "sb3"

    @property
    def gamma(self) -> float:
        """The discount factor of whichever algorithm is configured."""
        return (self.ppo or self.sac).gamma

    def with_overrides(
        self,
        *,
        steps: int | None = None,
        seed: int | None = None,
        envs: int | None = None,
        demonstrations: str | None = None,
        demonstrations_root: str | None = None,
    ) -> TrainingConfig:
        """This config with command-line overrides applied, validated again. ``demonstrations``
        names the dataset (the config's other ``demonstrations`` settings, or their defaults, kept)."""
        data = self.model_dump()
        for key, value in (("total_steps", steps), ("seed", seed), ("envs", envs)):
            if value is not None:
                data[key] = value
        if demonstrations is not None:
            data["demonstrations"] = {**(data.get("demonstrations") or {}), "dataset": demonstrations}
            if demonstrations_root is not None:
                data["demonstrations"]["root"] = demonstrations_root
        elif demonstrations_root is not None:
            raise UsageError("--demonstrations-root: give the dataset too (--demonstrations DATASET)")
        try:
            return TrainingConfig.model_validate(data)
        except ValidationError as exc:
            raise UsageError("; ".join(e["msg"] for e in exc.errors())) from None


def load_training_config(path: str | Path) -> TrainingConfig:
    """Load and validate a training config; raises :class:`SpecError` with located problems."""
    from ..spec.validation import problems_from_validation

    path = Path(path)
    if not path.is_file():
        raise SpecError.at(display(path), "training config not found")
    data, smap = load_located(path, display_path=display(path))
    try:
        return TrainingConfig.model_validate(data)
    except ValidationError as exc:
        raise SpecError(problems_from_validation(exc, data, smap, TrainingConfig)) from None


def training_schema() -> dict:
    """JSON Schema of a training config, for editors."""
    schema = TrainingConfig.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "assistive-compiler training config"
    return schema


def run_config(info: RunInfo) -> TrainingConfig:
    """The resolved training config a run directory's ``run.json`` records."""
    return TrainingConfig.model_validate(info.config)

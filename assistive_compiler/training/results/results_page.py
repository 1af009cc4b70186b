"""``results``: the learned-results section of ``docs/results.md``, regenerated from the shipped
policies alone (``pretrained/*/policy.json`` and ``curve.csv``).

Everything between the markers ``<!-- results:begin -->`` and ``<!-- results:end -->`` is written
here: Table I (static person) and Table II (active person) in the paper's terms — our mean return
± std, success rate and force on the person beside the paper's return for the same robot and its
best robot's success rate (§V) — with each cell's algorithm, env steps, wall time and env steps/s
including learning; the paper's §V-B claim (co-optimised against static success) where both cells
exist; and per cell its learning curve and a picture of one evaluation rollout. The prose around
the markers is written by hand. A test keeps the block equal to what this module writes.
"""

from __future__ import annotations

import json
from pathlib import Path

from .paper import PAPER, ROBOT_TITLES, TASK_TITLES, TASKS
from .table import best_per_cell, goals_met, markdown_table, table_rows

BEGIN, END = "<!-- results:begin -->", "<!-- results:end -->"
PICTURES = "results/cells"  # beside the doc: docs/results/cells/<name>-curve.png and <name>.png


def shipped_records() -> list[dict]:
    """Every shipped policy's ``policy.json``, by name."""
    from ...policies.mlp import POLICY_FILE
    from ...policies.pretrained import pretrained_dir, shipped_names

    return [json.loads((pretrained_dir() / n / POLICY_FILE).read_text()) for n in shipped_names()]


def _hours(seconds: float | None) -> str:
    if not seconds:
        return "—"
    return f"{seconds / 3600:.1f} h" if seconds >= 3600 else f"{seconds / 60:.0f} min"


def _started_from(demonstrations: dict | bool) -> str:
    """What a row started from, when not from the reward alone (``export`` records False or the
    run's ``demonstrations.json``): always said in the table."""
    if not isinstance(demonstrations, dict):
        return ""
    d = demonstrations
    kept = f", cloning kept in the actor's loss (weight {d['clone_weight']:g})" if d.get("clone_weight") else ""
    held = f", the actor held for SAC's first {d['hold_actor_steps']:,} updates" if d.get("hold_actor_steps") else ""
    return f" from {d['episodes']} {d['policy']} demonstrations ({d['steps']:,} steps){kept}{held}"


def _start_sentence(demonstrations: dict | bool) -> str:
    """How a run that started from demonstrations did so, for its cell's paragraph."""
    if not isinstance(demonstrations, dict):
        return ""
    d = demonstrations
    cloned = (
        f"the actor cloned on the {d['cloned_steps']:,} steps of the successful ones (squared error of its "
        f"actions {d['clone_mse_before']:.3f} → {d['clone_mse_after']:.4f})"
        if "clone_mse_after" in d
        else "no cloning"
    )
    return (
        f" Started from `{d['dataset']}`: {d['episodes']} episodes of the {d['policy']} policy "
        f"({d['successful_episodes']} successful, {d['steps']:,} steps); {cloned}, "
        f"{d['replayed_steps']:,} steps in the replay buffer, the critics warmed up for "
        f"{d['critic_warmup_steps']:,} gradient steps"
        + (
            f"; the actor then held for SAC's first {d['hold_actor_steps']:,} updates (the critics learning the "
            "cloned policy's returns online)"
            if d.get("hold_actor_steps")
            else ""
        )
        + (
            f"; SAC learned with the cloning term kept in its actor loss (weight {d['clone_weight']:g} × the "
            "demonstrated pairs' mean |Q|)."
            if d.get("clone_weight")
            else "."
        )
    )


def _row(r: dict, paper: dict, paper_success: dict) -> list[str]:
    e, sampled = r["evaluation"], r.get("evaluation_sampled")
    paper_return = paper.get(r["task"], {}).get(r["robot"])
    paper_s = paper_success.get(r["task"])
    # against the paper under its code's protocol (sampled actions) where the cell has that figure
    judged = sampled or e
    goal = "—" if paper_s is None else ("yes" if 100 * judged["success_rate"] >= paper_s else "no")
    return [
        TASK_TITLES.get(r["task"], r["task"]),
        ROBOT_TITLES.get(r["robot"], r["robot"]),
        r["label"] + _started_from(r["demonstrations"]),
        f"{r['trained_steps']:,}",
        _hours(r.get("wall_s")),
        "—" if not r.get("steps_per_s_including_learning") else f"{r['steps_per_s_including_learning']:.0f}",
        f"{e['mean_return']:.1f} ± {e['std_return']:.1f}",
        f"{100 * e['success_rate']:.0f}%",
        "—" if sampled is None else f"{sampled['mean_return']:.1f} ± {sampled['std_return']:.1f}",
        "—" if sampled is None else f"{100 * sampled['success_rate']:.0f}%",
        f"{e['mean_force_on_human_n']:.2f}",
        "—" if paper_return is None else f"{paper_return:.1f}",
        "—" if paper_s is None else f"{paper_s}%",
        goal + (" (sampled)" if sampled and paper_s is not None else ""),
    ]


HEADER = [
    "Task",
    "Robot",
    "Algorithm",
    "Env steps",
    "Wall time",
    "Env steps/s",
    "Return ± std",
    "Success",
    "Return ± std, sampled actions",
    "Success, sampled actions",
    "Force on person (N)",
    "Paper return",
    "Paper success (best robot)",
    "≥ paper",
]


def _order(r: dict) -> tuple:
    return (TASKS.index(r["task"]) if r["task"] in TASKS else len(TASKS), r["task"], r["robot"], r["name"])


def _settings(r: dict) -> tuple:
    """A cell's learning settings: its network and its algorithm's section of the config."""
    return (r["config"].get("network"), r["config"].get(r["algorithm"]))


def _claim_row(coop: dict, records: list[dict]) -> list[str] | None:
    """A co-optimised cell against the static-person cell of the same task, robot and algorithm —
    of the same settings where there is one — with the nearest budget: success with sampled actions
    where the policy kept its log-std, and with the mean action (env steps, policy), each; None when
    there is no such static cell."""
    static = [
        r
        for r in records
        if not r["coop"] and (r["task"], r["robot"], r["algorithm"]) == (coop["task"], coop["robot"], coop["algorithm"])
    ]
    if not static:
        return None
    s = min(static, key=lambda r: (_settings(r) != _settings(coop), abs(r["trained_steps"] - coop["trained_steps"])))

    def cell(r: dict) -> str:
        mean = f"{100 * r['evaluation']['success_rate']:.0f}% mean action"
        sampled = r.get("evaluation_sampled")
        figures = f"{100 * sampled['success_rate']:.0f}% sampled, {mean}" if sampled else mean
        return f"{figures} ({r['trained_steps']:,} steps, `{r['name']}`)"

    return [
        TASK_TITLES[coop["task"]],
        ROBOT_TITLES.get(coop["robot"], coop["robot"]),
        coop["algorithm"].upper(),
        cell(s),
        cell(coop),
    ]


def _sampled_sentence(sampled: dict | None) -> str:
    """The cell's figures under the reference code's protocol, where its export measured them."""
    if not sampled:
        return ""
    return (
        f"; actions sampled from the policy's Gaussian (the reference code's protocol), the same seeds: success "
        f"{100 * sampled['success_rate']:.0f}%, return {sampled['mean_return']:.1f} ± {sampled['std_return']:.1f}"
    )


#: Marks a paper-layout cell measured with the mean action only (a policy exported without its
#: log-std): the paper's code sampled its actions.
MEAN_ACTION_MARK = " *"
#: The budget of a cell of the paper-layout tables (env steps): this project's cells are trained
#: within it; policies trained beyond it — the anchor runs, the paper's PPO at its 10,000,000 steps
#: — are reported beside the table, not mixed into its cells.
CELL_BUDGET_STEPS = 1_000_000


def _paper_protocol_figures(records: list[dict]) -> list[dict]:
    """Each shipped policy's figures under the paper code's protocol (sampled actions) where its
    export measured it; a (table, task, robot) with no such policy keeps its mean-action figures,
    marked. Policies started from demonstrations are left out: the paper learned from the reward
    alone (they are rows of the full tables). ``table``'s best-of-cell rule then picks the highest
    return, as the paper kept the best of three seeds."""
    figures = []
    for r in records:
        if r["demonstrations"]:  # the paper learned from the reward alone
            continue
        e = r.get("evaluation_sampled") or r["evaluation"]
        figures.append(
            {
                **{k: e[k] for k in ("mean_return", "std_return", "success_rate", "episodes")},
                "coop": bool(r["coop"]),
                "task": r["task"],
                "robot": r["robot"],
                "trained_steps": r["trained_steps"],
                "run": r["name"],
                "sampled": r.get("evaluation_sampled") is not None,
                "mark": "" if r.get("evaluation_sampled") else MEAN_ACTION_MARK,
            }
        )
    sampled_cells = {(f["coop"], f["task"], f["robot"]) for f in figures if f["sampled"]}
    return [f for f in figures if f["sampled"] or (f["coop"], f["task"], f["robot"]) not in sampled_cells]


def _paper_layout(records: list[dict]) -> list[str]:
    """Tables I and II as the paper prints them: a row per task, a column per robot, each cell our
    mean return under the paper code's protocol with the paper's in parentheses; the success of our
    robot with the highest return beside the paper's best robot's; and the goals counted."""
    best = best_per_cell(_paper_protocol_figures([r for r in records if r["trained_steps"] <= CELL_BUDGET_STEPS]))
    anchors = _paper_protocol_figures([r for r in records if r["trained_steps"] > CELL_BUDGET_STEPS])
    parts = []
    for coop in (False, True):
        title = PAPER[coop][0]
        header, rows, _ = table_rows(best, coop)
        goals = goals_met(best, coop)
        used = sorted(
            (v for (c, _, _), v in best.items() if c == coop), key=lambda v: (TASKS.index(v["task"]), v["robot"])
        )
        parts += [
            f"### {title} in the paper's layout\n",
            "Mean return on the 100 test seeds with actions sampled from the policy (the paper code's protocol), ours "
            "in bold where it reaches the paper's (in parentheses, §V); Success: our robot with the highest return, "
            f"its success with sampled actions (the paper's best robot's). `{MEAN_ACTION_MARK.strip()}` the mean "
            "action only (a policy exported without its log-std). Where a task and robot have several shipped "
            "policies learned from the reward alone, the one with the highest return fills the cell.\n",
            markdown_table(header, rows) + "\n",
            f"Goals: our return reaches the paper's in {goals['returns_met']} of the {goals['returns_compared']} "
            f"cells measured (of {sum(len(v) for v in PAPER[coop][1].values())}); our best robot's success reaches "
            f"the paper's best robot's on {goals['successes_met']} of the {goals['successes_compared']} tasks "
            f"measured (of {len(PAPER[coop][2])}).\n",
            "Cells: "
            + "; ".join(
                f"{TASK_TITLES[v['task']]} × {ROBOT_TITLES.get(v['robot'], v['robot'])} `{v['run']}`" for v in used
            )
            + ".\n",
        ]
        parts += [_anchor_line(a, PAPER[coop][1]) for a in anchors if a["coop"] == coop]
    return parts


def _anchor_line(a: dict, paper: dict) -> str:
    """A policy trained beyond the cells' budget (an anchor run), beside the table it belongs to."""
    protocol = "the mean action" if a["mark"] else "sampled actions"
    paper_return = paper.get(a["task"], {}).get(a["robot"])
    return (
        f"Beside the table, trained beyond its cells' {CELL_BUDGET_STEPS:,} env steps: "
        f"{TASK_TITLES.get(a['task'], a['task'])} × {ROBOT_TITLES.get(a['robot'], a['robot'])} `{a['run']}` "
        f"({a['trained_steps']:,} env steps), with {protocol}: return {a['mean_return']:.1f} "
        f"({'—' if paper_return is None else f'{paper_return:.1f}'}), success {100 * a['success_rate']:.0f}%.\n"
    )


def results_block(records: list[dict]) -> str:
    """The generated Markdown between the markers (no pictures are made here)."""
    parts = [
        BEGIN,
        "<!-- written by `assistive-compiler results`; edit the policies or the prose outside the markers -->",
        "",
        *_paper_layout(records),
    ]
    for coop in (False, True):
        title, paper, paper_success = PAPER[coop]
        rows = sorted((r for r in records if bool(r["coop"]) == coop), key=_order)
        parts.append(f"### {title}\n")
        if not rows:
            parts.append("No cell of this table has been trained here yet.\n")
            continue
        missing = [TASK_TITLES[t] for t in TASKS if t in paper and not any(r["task"] == t for r in rows)]
        parts.append(markdown_table(HEADER, [_row(r, paper, paper_success) for r in rows]) + "\n")
        if missing:
            parts.append(f"Not trained yet: {', '.join(missing)}.\n")
    claim = [_claim_row(a, records) for a in sorted(records, key=_order) if a["coop"]]
    claim = [row for row in claim if row]
    parts.append("### The paper's claim (§V-B): an active person raises success\n")
    if claim:
        parts.append(
            "Each co-optimised cell beside the static-person cell of the same task, robot and algorithm "
            "(of the same settings where one has them, then the nearest budget); the same evaluation seeds, "
            "success with actions sampled from the policy (the paper code's protocol) where both kept their "
            "log-std, and with the mean action.\n"
        )
        parts.append(
            markdown_table(["Task", "Robot", "Algorithm", "Static person", "Active person (co-optimised)"], claim)
            + "\n"
        )
    else:
        parts.append(
            "Not measured yet: it needs a co-optimised cell beside a static one of the same task, robot and algorithm.\n"
        )
    parts.append("### Each cell\n")
    for r in sorted(records, key=_order):
        e = r["evaluation"]
        parts.append(
            f"#### {TASK_TITLES.get(r['task'], r['task'])} × {ROBOT_TITLES.get(r['robot'], r['robot'])}: {r['label']}\n"
        )
        parts.append(
            f"`--policy pretrained:{r['name']}`: {r['trained_steps']:,} env steps "
            f"({_hours(r.get('wall_s'))}), evaluated on {e['episodes']} episodes, seeds {e['seed']:,}–"
            f"{e['seed'] + e['episodes'] - 1:,} (never used in training), deterministic actions: success "
            f"{100 * e['success_rate']:.0f}%, return {e['mean_return']:.1f} ± {e['std_return']:.1f}"
            f"{_sampled_sentence(r.get('evaluation_sampled'))}. "
            f"{_compiled_tasks_sentence(r)}{_start_sentence(r['demonstrations'])}\n"
        )
        if r["trained_steps"] > 0:  # a policy shipped before its first env step has no curve
            parts.append(f"![{r['name']} learning curve]({PICTURES}/{r['name']}-curve.png)\n")
        parts.append(f"![{r['name']} rollout, seed {e['seed']:,}]({PICTURES}/{r['name']}.png)\n")
    parts.append(END)
    return "\n".join(parts)


def _compiled_tasks_sentence(record: dict) -> str:
    """Which compiled task the policy trained on, and which its figures were measured on where
    that is another (a policy evaluated again after a change of the code)."""
    from ..trained.reevaluate import evaluated_on

    trained, evaluated = record["content_hash"], evaluated_on(record)
    if evaluated == trained:
        return f"Trained and evaluated on the compiled task {trained[:12]}."
    earlier = record.get("earlier_evaluations") or []
    was = f" (at export: success {100 * earlier[0]['success_rate']:.0f}%)" if earlier else ""
    return (
        f"Trained on the compiled task {trained[:12]}; evaluated on {evaluated[:12]}, the task as the code "
        f"compiled it on {record.get('evaluated', 'a later date')}{was}."
    )


def write_pictures(records: list[dict], doc_dir: Path, progress=None) -> list[Path]:
    """Each cell's learning curve and a strip of its first evaluation episode (rendered anew)."""
    from ...policies.pretrained import PREFIX, load_trained, pretrained_dir
    from ..bookkeeping.curves import plot_curves, read_curve
    from ..trained.evaluate import compile_for_policy, write_rollout

    out_dir = doc_dir / PICTURES
    written = []
    for r in records:
        curve = read_curve(pretrained_dir() / r["name"] / "curve.csv")
        if curve:
            png = out_dir / f"{r['name']}-curve.png"
            plot_curves(
                {r["label"]: curve}, png, title=f"{r['gym_id'].split('/')[-1]}: {r['label']}, training episodes"
            )
            written.append(png)
        policy, _ = load_trained(PREFIX + r["name"])  # a co-optimised pair plays both agents
        png = out_dir / f"{r['name']}.png"
        write_rollout(compile_for_policy(r).out_dir, policy, r["coop"], r["evaluation"]["seed"], png)
        written.append(png)
        if progress:
            progress(r["name"])
    return written


def update_doc(doc: Path, records: list[dict]) -> str:
    """``doc`` with its generated block replaced (appended where the markers are missing)."""
    text = doc.read_text() if doc.is_file() else "# Training results measured here\n"
    block = results_block(records)
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        tail = rest.split(END, 1)[1]
        return head + block + tail
    return text.rstrip("\n") + "\n\n" + block + "\n"

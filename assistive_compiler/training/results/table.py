"""``table``: the paper's Tables I and II from run directories, our values beside the paper's.

Rows are tasks, columns robots, in the paper's layout; each cell is our mean return over the
evaluation episodes with the paper's in parentheses, and the last column the success rate of the
robot with the highest mean return (ours, then the paper's). Static runs fill Table I, co-optimised
runs Table II. Where several runs share a (task, robot) — seeds — the one with the highest mean
return is shown, as the paper keeps the best of three seeds. Each run's figures come from its
``evaluation.json`` (written by ``evaluate``); a run without one is evaluated first.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

from ...paths import display
from ...run_dir import RunDir
from .paper import PAPER, ROBOT_TITLES, ROBOTS, TASK_TITLES, TASKS

EVALUATION_FILE = "evaluation.json"
#: Marks a cell whose run started from demonstrations (train --demonstrations), not from the reward alone.
DEMONSTRATIONS_MARK = " †"


def run_figures(run_dir: str | Path, episodes: int | None = None, seed: int = 0) -> dict:
    """The run's evaluation (read from ``evaluation.json``, or computed and written there)."""
    from ..trained.evaluate import evaluate, save_evaluation

    run = RunDir(run_dir)
    run.info()  # a clear error when this is not a run directory
    file = run.path / EVALUATION_FILE
    if file.is_file():
        return json.loads(file.read_text())
    result = evaluate(run.path, episodes=episodes, seed=seed)
    save_evaluation(run, result)
    return result


def best_per_cell(results: list[dict]) -> dict[tuple[bool, str, str], dict]:
    """(co-op, task, robot) -> the evaluation with the highest mean return among its runs."""
    best: dict[tuple[bool, str, str], dict] = {}
    for r in results:
        key = (bool(r["coop"]), r["task"], r["robot"])
        if key not in best or r["mean_return"] > best[key]["mean_return"]:
            best[key] = r
    return best


def _fmt(value: float | None, digits: int = 1) -> str:
    return "—" if value is None else f"{value:.{digits}f}"


def table_rows(best: dict, coop: bool) -> tuple[list[str], list[list[str]], list[dict]]:
    """Header, Markdown cells and CSV records of Table I (``coop`` False) or II (True)."""
    _, paper, paper_success = PAPER[coop]
    robots = list(ROBOTS) + sorted({r for (c, _, r) in best if c == coop and r not in ROBOTS})
    tasks = [t for t in TASKS if t in paper] + sorted({t for (c, t, _) in best if c == coop and t not in TASKS})
    header = ["Task"] + [ROBOT_TITLES.get(r, r) for r in robots] + ["Success"]
    rows, records = [], []
    for task in tasks:
        cells = [TASK_TITLES.get(task, task)]
        ours = {r: best.get((coop, task, r)) for r in robots}
        for robot in robots:
            paper_value = paper.get(task, {}).get(robot)
            mine = ours[robot]
            mark = DEMONSTRATIONS_MARK if mine and mine.get("demonstrations") else ""
            cells.append(f"{_fmt(mine['mean_return'] if mine else None)}{mark} ({_fmt(paper_value)})")
            records.append(
                {
                    "table": "II" if coop else "I",
                    "task": task,
                    "robot": robot,
                    "mean_return": mine["mean_return"] if mine else None,
                    "std_return": mine["std_return"] if mine else None,
                    "success_rate": mine["success_rate"] if mine else None,
                    "episodes": mine["episodes"] if mine else None,
                    "trained_steps": mine["trained_steps"] if mine else None,
                    "run": mine["run"] if mine else None,
                    "demonstrations": bool(mine.get("demonstrations")) if mine else None,
                    "paper_mean_return": paper_value,
                }
            )
        evaluated = {r: v for r, v in ours.items() if v is not None}
        top = max(evaluated.values(), key=lambda v: v["mean_return"]) if evaluated else None
        ours_success = (
            f"{100 * top['success_rate']:.0f}% {ROBOT_TITLES.get(top['robot'], top['robot'])}" if top else "—"
        )
        paper_s = paper_success.get(task)
        cells.append(f"{ours_success} ({'—' if paper_s is None else f'{paper_s}%'})")
        rows.append(cells)
    return header, rows, records


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def make_tables(run_dirs: list[str], out: str | None = None, episodes: int | None = None, seed: int = 0) -> str:
    """The Markdown report; with ``out`` (``results.md``) also ``results.csv`` and ``results.png``."""
    from ..bookkeeping.curves import plot_curves, read_curve

    results = [run_figures(d, episodes, seed) for d in run_dirs]
    best = best_per_cell(results)
    parts, records = [], []
    for coop in (False, True):
        if not any(c == coop for (c, _, _) in best):
            continue
        title = PAPER[coop][0]
        header, rows, recs = table_rows(best, coop)
        records += recs
        parts.append(
            f"### {title}\n\nMean return over the evaluation episodes, ours (paper, §V); "
            f"Success: the best robot's success rate, ours (paper).\n\n{markdown_table(header, rows)}\n"
        )
    used = sorted({(r["run"], r["episodes"], r["trained_steps"], r["seed"]) for r in best.values()})
    parts.append(
        "Runs: "
        + "; ".join(f"`{run}` ({steps:,} steps, {n} episodes from seed {s})" for run, n, steps, s in used)
        + "\n"
    )
    if any(r.get("demonstrations") for r in best.values()):
        parts.append(f"{DEMONSTRATIONS_MARK.strip()} started from demonstrations (`train --demonstrations`).\n")
    text = "\n".join(parts)
    if out:
        out_md = Path(out)
        out_md.parent.mkdir(parents=True, exist_ok=True)
        curves = {Path(r["run"]).name: read_curve(RunDir(r["run"]).curve_csv) for r in best.values()}
        figure = out_md.with_suffix(".png")
        plot_curves({k: v for k, v in curves.items() if v}, figure, title="learning curves")
        out_md.write_text(text + f"\n![learning curves]({figure.name})\n")
        with out_md.with_suffix(".csv").open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(records[0]) if records else ["table"])
            writer.writeheader()
            writer.writerows(records)
        text += f"\nwrote {display(out_md)}, {display(out_md.with_suffix('.csv'))}, {display(figure)}\n"
    return text

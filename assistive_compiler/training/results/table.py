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


def paper_best_robot(paper: dict, task: str) -> str | None:
    """The robot with the paper's highest mean return on ``task`` (whose success the paper reports)."""
    returns = paper.get(task)
    return max(returns, key=returns.get) if returns else None


def _cell(mine: dict | None, paper_value: float | None) -> str:
    """``ours (paper)``; ours in bold where it reaches the paper's, with its marks (``mark``:
    what the cell's figure is, e.g. the mean action where the paper sampled; † demonstrations)."""
    if mine is None:
        return f"— ({_fmt(paper_value)})"
    ours = _fmt(mine["mean_return"])
    if paper_value is not None and mine["mean_return"] >= paper_value:
        ours = f"**{ours}**"
    mark = (DEMONSTRATIONS_MARK if mine.get("demonstrations") else "") + mine.get("mark", "")
    return f"{ours}{mark} ({_fmt(paper_value)})"


def table_rows(best: dict, coop: bool) -> tuple[list[str], list[list[str]], list[dict]]:
    """Header, Markdown cells and CSV records of Table I (``coop`` False) or II (True): per task,
    each robot's mean return beside the paper's, the success of our robot with the highest return
    beside the paper's best robot's, and whether that robot is the paper's."""
    _, paper, paper_success = PAPER[coop]
    robots = list(ROBOTS) + sorted({r for (c, _, r) in best if c == coop and r not in ROBOTS})
    tasks = [t for t in TASKS if t in paper] + sorted({t for (c, t, _) in best if c == coop and t not in TASKS})
    header = ["Task"] + [ROBOT_TITLES.get(r, r) for r in robots] + ["Success", "Best robot as the paper's"]
    rows, records = [], []
    for task in tasks:
        cells = [TASK_TITLES.get(task, task)]
        ours = {r: best.get((coop, task, r)) for r in robots}
        for robot in robots:
            paper_value = paper.get(task, {}).get(robot)
            mine = ours[robot]
            cells.append(_cell(mine, paper_value))
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
        top = _best_robot(ours)
        ours_success = (
            f"{100 * top['success_rate']:.0f}%{top.get('mark', '')} {ROBOT_TITLES.get(top['robot'], top['robot'])}"
            if top
            else "—"
        )
        paper_s, paper_top = paper_success.get(task), paper_best_robot(paper, task)
        cells.append(
            f"{ours_success} ({'—' if paper_s is None else f'{paper_s}%'}"
            + (f" {ROBOT_TITLES.get(paper_top, paper_top)})" if paper_top else ")")
        )
        cells.append(_same_best_robot(ours, top, paper_top))
        rows.append(cells)
    return header, rows, records


def _best_robot(ours: dict[str, dict | None]) -> dict | None:
    """Our robot with the highest mean return on a task, among the paper's four where any of them
    has a cell (the paper's comparison; later robots are columns beside it), else among all."""
    evaluated = {r: v for r, v in ours.items() if v is not None}
    among = {r: v for r, v in evaluated.items() if r in ROBOTS} or evaluated
    return max(among.values(), key=lambda v: v["mean_return"]) if among else None


def _same_best_robot(ours: dict[str, dict | None], top: dict | None, paper_top: str | None) -> str:
    """Whether our best robot on a task is the paper's: said once all the paper's robots have a cell."""
    if top is None or paper_top is None:
        return "—"
    missing = [r for r in ROBOTS if ours.get(r) is None]
    if missing:
        return f"— ({len(ROBOTS) - len(missing)} of {len(ROBOTS)} robots measured)"
    return "yes" if top["robot"] == paper_top else f"no ({ROBOT_TITLES.get(top['robot'], top['robot'])})"


def goals_met(best: dict, coop: bool) -> dict[str, int]:
    """The paper's goals counted over Table I (``coop`` False) or II: cells whose return reaches the
    paper's (of the cells both have), and tasks whose best robot's success reaches the paper's best
    robot's (of the tasks we have a cell of)."""
    _, paper, paper_success = PAPER[coop]
    cells = [(v, paper[t][r]) for (c, t, r), v in best.items() if c == coop and r in paper.get(t, {})]
    tasks = {}
    for t in {t for (c, t, _) in best if c == coop and t in paper_success}:
        top = _best_robot({r: v for (c, task, r), v in best.items() if c == coop and task == t})
        if top is not None:
            tasks[t] = top
    return {
        "returns_met": sum(v["mean_return"] >= p for v, p in cells),
        "returns_compared": len(cells),
        "successes_met": sum(100 * v["success_rate"] >= paper_success[t] for t, v in tasks.items()),
        "successes_compared": len(tasks),
    }


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

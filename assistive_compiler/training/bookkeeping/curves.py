"""Learning curves: a run's ``curve.csv`` (its columns, reading it, cutting it at a checkpoint) and
plotting one or more runs (matplotlib, Agg)."""

from __future__ import annotations

import csv
from pathlib import Path

from ...run_dir import write_atomic

CURVE_FIELDS = ("steps", "wall_s", "episodes", "mean_return", "success_rate", "steps_per_s")


def read_curve(path: Path) -> list[dict[str, float]]:
    """The rows of a ``curve.csv`` as numbers (an empty list when there is none yet); a row cut
    short by a killed process (the last one) is left out."""
    if not Path(path).is_file():
        return []
    with Path(path).open() as f:
        return [row for row in map(_numbers, csv.DictReader(f)) if row is not None]


def _numbers(row: dict) -> dict[str, float] | None:
    """A curve row's values as numbers; None for a row torn by a killed process (None or '' fields)."""
    try:
        return {k: float(v) for k, v in row.items()}
    except (TypeError, ValueError):
        return None


def cut_curve(src: Path, dst: Path, steps: float) -> list[dict[str, float]]:
    """Write the rows of ``src`` at or before ``steps`` env steps to ``dst`` as they are written
    (atomically; ``dst`` may be ``src``), a torn row left out; returns those rows."""
    header, *lines = Path(src).read_text().splitlines()
    kept, rows = [header], []
    for line in lines:
        parsed = next(csv.DictReader([header, line]), None)  # as read_curve reads it: short rows get None
        row = _numbers(parsed) if parsed is not None else None
        if row is not None and row["steps"] <= steps:
            kept.append(line)
            rows.append(row)
    write_atomic(Path(dst), "\n".join(kept) + "\n")
    return rows


def plot_curves(
    curves: dict[str, list[dict[str, float]]], out: Path, title: str = "", baselines: dict[str, float] | None = None
) -> None:
    """Mean episode return and success rate against env steps, one line per run.

    ``baselines``: horizontal reference lines of the return (e.g. random and scripted policies)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_r, ax_s) = plt.subplots(1, 2, figsize=(11, 4))
    for label, rows in curves.items():
        steps = [r["steps"] for r in rows]
        ax_r.plot(steps, [r["mean_return"] for r in rows], label=label)
        ax_s.plot(steps, [100 * r["success_rate"] for r in rows], label=label)
    for name, value in (baselines or {}).items():
        ax_r.axhline(value, linestyle="--", linewidth=1, color="grey")
        ax_r.annotate(name, (0, value), textcoords="offset points", xytext=(4, 3), fontsize=8, color="dimgrey")
    ax_r.set(xlabel="env steps", ylabel="mean episode return", title="return")
    ax_s.set(xlabel="env steps", ylabel="success rate (%)", title="success", ylim=(-2, 102))
    for ax in (ax_r, ax_s):
        ax.grid(alpha=0.3)
    if len(curves) > 1:
        ax_r.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=100)
    plt.close(fig)

"""Learning curves: reading a run's ``curve.csv`` and plotting one or more runs (matplotlib, Agg)."""

from __future__ import annotations

import csv
from pathlib import Path


def read_curve(path: Path) -> list[dict[str, float]]:
    """The rows of a ``curve.csv`` as numbers (an empty list when there is none yet); a row cut
    short by a killed process (the last one) is left out."""
    if not Path(path).is_file():
        return []
    rows = []
    with Path(path).open() as f:
        for row in csv.DictReader(f):
            try:
                rows.append({k: float(v) for k, v in row.items()})
            except (TypeError, ValueError):  # a torn row: None or '' fields
                continue
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

"""What a training run reports as it learns, the same for every engine: the progress bar, the
learning curve (``curve.csv``) and the per-term TensorBoard scalars, as Isaac Lab logs them:
``Episode_Reward/<term>`` is each reward term's weighted episode sum, averaged over the episodes
that ended since the last update, beside ``Episode/return`` and ``Episode/success_rate``."""

from __future__ import annotations

import csv
import sys
import time

import numpy as np

from ...run_dir import RunDir
from .curves import CURVE_FIELDS, cut_curve


def print_reward_table(weights: dict[str, float], title: str, out=sys.stderr) -> None:
    """The active reward terms and their weights, printed when training starts."""
    width = max(len(n) for n in weights) if weights else 4
    print(f"{title}: reward = Σ weight × term", file=out)
    print(f"  {'term':<{width}}  weight", file=out)
    for name, weight in weights.items():
        print(f"  {name:<{width}}  {weight:+g}", file=out)


class TrainingBar:
    """Training progress on stderr, with rich (as every other command's progress): a live bar on a
    terminal; elsewhere (a log file of a background run) one plain line per update."""

    def __init__(self, total_steps: int, start_steps: int, *, enabled: bool = True):
        self.total, self.enabled, self.live = total_steps, enabled, enabled and sys.stderr.isatty()
        self._last = ""
        if self.live:
            from rich.console import Console
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

            self.progress = Progress(
                TextColumn("train"),
                BarColumn(),
                TextColumn("{task.completed:,}/{task.total:,} steps"),
                TextColumn("{task.fields[status]}"),
                TimeElapsedColumn(),
                console=Console(file=sys.stderr, highlight=False),
            )
            self.task = self.progress.add_task("train", total=total_steps, completed=start_steps, status="")
            self.progress.start()

    def update(self, steps: int, status: str) -> None:
        if self.live:
            self.progress.update(self.task, completed=steps, status=status)
        elif self.enabled:
            print(f"train {steps:,}/{self.total:,} steps  {status}", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.live:
            self.progress.stop()


class Progress:
    """Collects finished episodes and, at each update, writes one curve row and TensorBoard point."""

    def __init__(
        self, run: RunDir, weights: dict[str, float], total_steps: int, start_steps: int, *, quiet: bool = False
    ):
        from torch.utils.tensorboard import SummaryWriter

        self.run, self.weights = run, weights
        self.writer = SummaryWriter(str(run.tb / "episodes"))
        self.start_steps, self.t0 = start_steps, time.perf_counter()
        self.wall_before, self.episodes = self._previous_totals()
        #: (episodes, mean return, success rate, each term's mean weighted episode sum) since the last update
        self.pending: list[tuple[int, float, float, dict[str, float]]] = []
        self.last_return: float | None = None
        self.bar = TrainingBar(total_steps, start_steps, enabled=not quiet)
        new = not run.curve_csv.is_file()
        self._csv = run.curve_csv.open("a", newline="")
        self._rows = csv.writer(self._csv)
        if new:
            self._rows.writerow(CURVE_FIELDS)

    def _previous_totals(self) -> tuple[float, int]:
        """Wall seconds and episodes of the run before this session (resumed runs). The curve is
        first cut back to the resumed checkpoint: rows written after it (and a row torn by a killed
        process) belong to training that the resumed run does again."""
        if not self.run.curve_csv.is_file():
            return 0.0, 0
        rows = cut_curve(self.run.curve_csv, self.run.curve_csv, self.start_steps)
        return (rows[-1]["wall_s"], int(rows[-1]["episodes"])) if rows else (0.0, 0)

    def episode(self, ret: float, success: bool, term_sums: dict[str, float]) -> None:
        """One finished episode: its return, success and unweighted term sums."""
        self.pending.append(
            (1, float(ret), float(success), {n: w * term_sums.get(n, 0.0) for n, w in self.weights.items()})
        )

    def episodes_summary(
        self, count: int, mean_return: float, success_rate: float, weighted_term_means: dict[str, float]
    ) -> None:
        """``count`` finished episodes given by their means (engines that aggregate episodes
        themselves); ``weighted_term_means``: each term's weighted episode sum, averaged."""
        self.pending.append((count, float(mean_return), float(success_rate), dict(weighted_term_means)))

    def update(self, steps: int) -> dict[str, float]:
        """Record the episodes since the last update at ``steps`` env steps; returns the scalars."""
        elapsed = time.perf_counter() - self.t0
        rate = (steps - self.start_steps) / elapsed if elapsed > 0 else 0.0
        scalars: dict[str, float] = {"Perf/steps_per_s": rate}
        if self.pending:
            counts = np.array([c for c, _, _, _ in self.pending], dtype=float)
            mean = lambda values: float(np.dot(counts, values) / counts.sum())  # noqa: E731
            scalars["Episode/return"] = mean([r for _, r, _, _ in self.pending])
            scalars["Episode/success_rate"] = mean([s for _, _, s, _ in self.pending])
            for name in self.weights:
                scalars[f"Episode_Reward/{name}"] = mean([t.get(name, 0.0) for _, _, _, t in self.pending])
            self.episodes += int(counts.sum())
            self.last_return = scalars["Episode/return"]
            self._rows.writerow(
                [
                    steps,
                    round(self.wall_before + elapsed, 3),
                    self.episodes,
                    scalars["Episode/return"],
                    scalars["Episode/success_rate"],
                    round(rate, 1),
                ]
            )
            self._csv.flush()
            self.pending.clear()
        for key, value in scalars.items():
            self.writer.add_scalar(key, value, steps)
        self.writer.flush()
        status = f"{rate:.0f} steps/s"
        if self.last_return is not None:
            status += (
                f", return {self.last_return:.1f}, success {scalars.get('Episode/success_rate', float('nan')):.2f}"
            )
        self.bar.update(steps, status)
        return scalars

    def wall_s(self) -> float:
        return self.wall_before + time.perf_counter() - self.t0

    def close(self) -> None:
        self.bar.close()
        self.writer.close()
        self._csv.close()

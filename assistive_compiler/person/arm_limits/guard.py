"""The reference's revert-to-last-valid rule (:class:`ArmLimitGuard`), independent of pybullet."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .convention import ArmLimitModel, Side, _check_side


class ArmLimitGuard:
    """The reference's rule (paper §III-C), without pybullet: after each physics sub-step the arm's
    four angles are checked; a valid pose becomes the last valid pose, an invalid one is replaced
    by the last valid pose (the caller resets the four joints to it with zero velocity). Before
    any valid pose has been seen there is nothing to revert to and the pose is left alone, as in
    the reference."""

    def __init__(self, model: ArmLimitModel, side: Side) -> None:
        if not callable(getattr(model, "valid", None)):
            raise TypeError(f"model must have a valid(q, side) method, got {type(model).__name__}")
        self.model = model
        self.side = _check_side(side)
        self._last: np.ndarray | None = None

    @property
    def last_valid(self) -> np.ndarray | None:
        """The last valid pose (a copy), or None."""
        return None if self._last is None else self._last.copy()

    def reset(self, q0: np.ndarray | Sequence[float] | None = None) -> bool:
        """Forget the history; then, if ``q0`` is given, check it (stored when valid). Returns
        whether a valid pose is now stored."""
        self._last = None
        if q0 is not None:
            self.check(q0)
        return self._last is not None

    def check(self, q: np.ndarray | Sequence[float]) -> tuple[np.ndarray, bool]:
        """``(q_out, reverted)``: ``(q, False)`` when q is valid (q is stored), ``(last valid,
        True)`` when it is not and a valid pose exists, else ``(q, False)``."""
        pose = np.array(q, dtype=float)
        if pose.shape != (4,):
            raise ValueError(f"q must have shape (4,), got {pose.shape}")
        if bool(self.model.valid(pose, self.side)):
            self._last = pose
            return pose.copy(), False
        if self._last is None:
            return pose, False
        return self._last.copy(), True

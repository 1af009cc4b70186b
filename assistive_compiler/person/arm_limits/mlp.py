"""A user-supplied MLP arm-limit model given as NumPy weights (:class:`MLPArmLimits`, ``.npz``)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .convention import Side, _as_poses, reference_input

_ACTIVATIONS = {
    "tanh": np.tanh,
    "sigmoid": lambda x: 1.0 / (1.0 + np.exp(-x)),
    "relu": lambda x: np.maximum(x, 0.0),
    "linear": lambda x: x,
}
_LAYER_KEY = re.compile(r"^([Wb])(\d+)$")


class MLPArmLimits:
    """A small dense network (Keras ``Dense`` semantics: ``y = x @ W + b``) classifying arm poses,
    evaluated with the reference's input convention (:func:`reference_input`); valid where the
    output is >= ``threshold`` (0.5, as Keras ``predict_classes`` on a sigmoid output).

    The network sees raw angles only, so, like the reference, it does not itself enforce the
    pose-independent box (the simulator's joint limits do)."""

    def __init__(
        self,
        weights: Sequence[np.ndarray],
        biases: Sequence[np.ndarray],
        activations: Sequence[str] | None = None,
        *,
        threshold: float = 0.5,
        source: str = "<arrays>",
    ) -> None:
        self.source = source
        ws = [np.asarray(w, dtype=float) for w in weights]
        bs = [np.asarray(b, dtype=float) for b in biases]
        n = len(ws)
        if n == 0 or len(bs) != n:
            raise ValueError(f"{source}: need as many biases as weight matrices (got {n} and {len(bs)})")
        for i, (w, b) in enumerate(zip(ws, bs)):
            if w.ndim != 2:
                raise ValueError(f"{source}: W{i} must be 2-D (inputs x outputs), got shape {w.shape}")
            if b.shape != (w.shape[1],):
                raise ValueError(
                    f"{source}: shape mismatch: b{i} has shape {b.shape}, "
                    f"expected ({w.shape[1]},) to match W{i} {w.shape}"
                )
            if i > 0 and w.shape[0] != ws[i - 1].shape[1]:
                raise ValueError(
                    f"{source}: shape mismatch between layers: W{i - 1} outputs {ws[i - 1].shape[1]} "
                    f"but W{i} takes {w.shape[0]} inputs"
                )
            if not (np.all(np.isfinite(w)) and np.all(np.isfinite(b))):
                raise ValueError(f"{source}: W{i}/b{i} contain non-finite values")
        if ws[0].shape[0] != 4:
            raise ValueError(
                f"{source}: input size must be 4 (shoulder_x, shoulder_y, shoulder_z, elbow), W0 takes {ws[0].shape[0]}"
            )
        if ws[-1].shape[1] != 1:
            raise ValueError(f"{source}: output size must be 1, W{n - 1} gives {ws[-1].shape[1]}")
        if activations is None:
            acts = ["tanh"] * (n - 1) + ["sigmoid"]
        else:
            acts = [str(a).strip().lower() for a in activations]
            if len(acts) != n:
                raise ValueError(f"{source}: 'activations' has {len(acts)} entries for {n} layers")
            bad = sorted({a for a in acts if a not in _ACTIVATIONS})
            if bad:
                raise ValueError(f"{source}: unknown activation(s) {bad}; known: {sorted(_ACTIVATIONS)}")
        self.weights = ws
        self.biases = bs
        self.activations = tuple(acts)
        self._fns = [_ACTIVATIONS[a] for a in acts]
        self.threshold = float(threshold)

    @classmethod
    def from_npz(cls, path: str | Path, *, threshold: float = 0.5) -> MLPArmLimits:
        """Load ``W0, b0, W1, b1, ...`` (Dense kernels of shape (in, out) and biases) and an
        optional ``activations`` string array (default: tanh hidden layers, sigmoid output).
        Raises ``ValueError`` naming the file and the problem."""
        path = Path(path)
        src = str(path)
        if not path.is_file():
            raise ValueError(f"{src}: no such file")
        try:
            with np.load(path, allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files}
        except Exception as exc:  # zipfile.BadZipFile, OSError, ValueError (pickled arrays), ...
            raise ValueError(f"{src}: not a readable .npz archive ({exc})") from exc
        indices: dict[str, set[int]] = {"W": set(), "b": set()}
        for key in arrays:
            m = _LAYER_KEY.match(key)
            if m:
                indices[m.group(1)].add(int(m.group(2)))
        if not indices["W"]:
            raise ValueError(f"{src}: missing arrays: no W0 (expected W0, b0, W1, b1, ...)")
        n = max(indices["W"] | indices["b"]) + 1
        missing = [f"{kind}{i}" for i in range(n) for kind in ("W", "b") if i not in indices[kind]]
        if missing:
            raise ValueError(f"{src}: missing arrays: {', '.join(missing)}")
        activations = None
        if "activations" in arrays:
            acts = arrays["activations"]
            if acts.dtype.kind not in "US":
                raise ValueError(f"{src}: 'activations' must be an array of strings, got dtype {acts.dtype}")
            activations = [a.decode() if isinstance(a, bytes) else str(a) for a in acts.ravel()]
        return cls(
            [arrays[f"W{i}"] for i in range(n)],
            [arrays[f"b{i}"] for i in range(n)],
            activations,
            threshold=threshold,
            source=src,
        )

    def predict(self, q: np.ndarray | Sequence[float], side: Side) -> np.ndarray:
        """The network's output for each pose, shape (N,)."""
        x = reference_input(q, side)
        for w, b, fn in zip(self.weights, self.biases, self._fns):
            x = fn(x @ w + b)
        return x[:, 0]

    def valid(self, q: np.ndarray | Sequence[float], side: Side) -> np.ndarray:
        """Boolean validity of one pose (shape ()) or a batch (shape (N,))."""
        _, single = _as_poses(q)
        with np.errstate(over="ignore"):
            ok = self.predict(q, side) >= self.threshold
        return ok[0] if single else ok

"""The episode recording format: one ``.npz`` file per episode, readable without pybullet.

A recording holds what an episode *looked like* and what it *scored*, step by step, so that it can
be replayed (viewed, plotted, compared) without simulating again. Files are written by
:class:`~assistive_compiler.record.RecordEpisodes` (``run --record DIR``) and read by
:func:`load_recording`. Written to a temporary name and renamed, so a file is complete or absent.

Layout of ``DIR``: ``episode-0000.npz``, ``episode-0001.npz``, ... in the order they were played.

Every file is a NumPy ``.npz`` archive (zip, deflate-compressed; no pickles). Index ``k = 0`` of the
per-state arrays is the state right after ``reset()``; ``k ≥ 1`` the state after the k-th env step,
at time ``k · dt`` (``dt`` = time step × frame skip, in the header). ``T`` = number of env steps,
``L`` = recorded links, ``O`` observation size, ``A`` action size, ``K`` reward terms.

``header`` — uint8 bytes of one UTF-8 JSON object:
    ``format`` ("assistive-compiler-episode"), ``format_version`` (1), ``task``, ``robot``,
    ``gym_id``, ``content_hash`` (the artifact's, see :mod:`assistive_compiler.artifact`), ``seed``
    (null for an unseeded reset), ``policy`` (a name, or null), ``episode`` (index in its
    directory), ``person_variant`` (the active variant's name), ``person_body`` (its body name),
    ``start`` (the precomputed start drawn), ``dt`` (s), ``steps`` (T), ``complete`` (false when
    the episode was cut short by a reset or close), ``return`` (Σ rewards), ``success`` (bool, the
    last step's ``task_success``), ``success_metric``,
    ``bodies`` (per body: ``name``, ``kind`` (robot, person, furniture, tool, garment),
    ``urdf`` (path in the artifact; a garment: its OBJ), ``links`` (URDF link names, in column order)),
    ``links`` (L pairs [body, link]: the columns of ``link_pos``/``link_quat``),
    ``terms`` (K names: the columns of ``terms``), ``term_weights`` and ``term_categories``
    (reward | preference, per name), ``targets`` (names: the columns of ``target_pos``),
    ``particles`` (per set: ``name``, ``count``, ``radius`` m, ``colors`` RGBA),
    ``markers`` (per set: ``name``, ``count``, ``radius`` m, ``rgba``),
    ``garments`` (per garment: ``name``, ``nodes``).

Arrays (world frame, metres, quaternions (x, y, z, w) as pybullet gives them):
    ``link_pos``     (T+1, L, 3) float64 — each link's URDF frame origin (a base: the URDF base
                     frame, not its centre of mass). Parked bodies (inactive person variants) are
                     far away, beyond the floor's edge.
    ``link_quat``    (T+1, L, 4) float64 — each link's URDF frame orientation.
    ``observations`` (T+1, O) float32 — the robot's observation after reset and after each step.
    ``actions``      (T, A) float64 — the action passed to step k (before the env clips it).
    ``rewards``      (T,) float64 — the reward of step k (Σ weight × term).
    ``terms``        (T, K) float64 — each reward term's unweighted value at step k (preference costs included).
    ``task_success`` (T,) int8 — 1 once the task's success criterion holds.
    ``success_metric`` (T,) float64 — the success term's aggregate so far.
    ``force_on_human`` (T,) float64 — contact force of robot, tools and garments on the person, N.
    ``target_pos``   (T+1, n_targets, 3) float64 — every target (e.g. the mouth, an itch spot).
    ``particles/<set>``        (T+1, n, 3) float64 — where each particle appears (a particle at
                               rest in its container: where the container carries it).
    ``particles_active/<set>`` (T+1, n) bool — not yet consumed or lost.
    ``markers/<set>``          (T+1, n, 3) float64 — each marker on the person.
    ``markers_remaining/<set>`` (T+1, n) bool — not yet cleared.
    ``garment/<name>``         (T+1, nodes, 3) float64 — the cloth's node positions.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

FORMAT = "assistive-compiler-episode"
FORMAT_VERSION = 1


@dataclass
class Recording:
    """One recorded episode: the JSON header and the arrays described in the module docstring."""

    header: dict
    arrays: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def steps(self) -> int:
        """Number of env steps T (the per-state arrays have T + 1 rows)."""
        return int(self.arrays["rewards"].shape[0])

    def link_index(self, body: str, link: str) -> int:
        """Column of (body, link) in ``link_pos``/``link_quat``."""
        return self.header["links"].index([body, link])

    def pose(self, k: int, body: str, link: str) -> tuple[np.ndarray, np.ndarray]:
        """World pose (position m, quaternion xyzw) of a link's URDF frame at state k."""
        j = self.link_index(body, link)
        return self.arrays["link_pos"][k, j], self.arrays["link_quat"][k, j]

    def term(self, name: str) -> np.ndarray:
        """(T,) unweighted values of one reward term."""
        return self.arrays["terms"][:, self.header["terms"].index(name)]

    def save(self, path: str | Path) -> Path:
        """Write atomically: a temporary file in the same directory, renamed when complete."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        header = np.frombuffer(json.dumps(self.header, sort_keys=True).encode(), dtype=np.uint8)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".npz.part")
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez_compressed(f, header=header, **self.arrays)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        return path


class RecordingError(ValueError):
    """A file that is not an episode recording (or of a newer format)."""


def load_recording(path: str | Path) -> Recording:
    """Read a recording written by :meth:`Recording.save` (no pickles are loaded)."""
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {name: data[name] for name in data.files}
    except (OSError, ValueError) as exc:
        raise RecordingError(f"{path}: not an episode recording (.npz): {exc}") from None
    if "header" not in arrays:
        raise RecordingError(f"{path}: not an episode recording: no 'header' array")
    header = json.loads(arrays.pop("header").tobytes().decode())
    if header.get("format") != FORMAT:
        raise RecordingError(f"{path}: not an episode recording: format {header.get('format')!r}, expected {FORMAT!r}")
    if header.get("format_version", 0) > FORMAT_VERSION:
        raise RecordingError(
            f"{path}: recording format version {header['format_version']} is newer than this reader's ({FORMAT_VERSION})"
        )
    return Recording(header, arrays)


def episode_files(directory: str | Path) -> list[Path]:
    """The recordings of a directory, in the order they were played."""
    return sorted(Path(directory).glob("episode-*.npz"))

"""A compiled task travels with a job (assistive_compiler.bundle): packed from the driver's
artifact, unpacked into another machine's cache under its content hash, checked, and refused when
damaged or when the worker's assistive-compiler differs from the driver's."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from assistive_compiler import bundle
from assistive_compiler.errors import UsageError
from assistive_compiler.runtime.env import AssistiveEnv


def test_a_packed_task_unpacks_elsewhere_and_runs_the_same_episode(artifact, tmp_path):
    packed = pickle.loads(pickle.dumps(bundle.pack(artifact)))  # as Ray ships an env config
    assert sum(len(b) for b in packed["files"].values()) < 1_000_000 and "manifest.json" in packed["files"]
    where = bundle.unpack(packed, cache=tmp_path / "worker-cache")
    assert where == tmp_path / "worker-cache" / "jobs" / packed["content_hash"]
    assert bundle.unpack(packed, cache=tmp_path / "worker-cache") == where  # a second env runner reuses it
    returns = []
    for directory in (artifact, where):
        env = AssistiveEnv(directory)
        env.reset(seed=3)
        actions = np.random.default_rng(0).uniform(-1, 1, (20, env.action_space.shape[0])).astype(np.float32)
        returns.append([env.step(a)[1] for a in actions])
        env.close()
    assert returns[0] == returns[1]


def test_a_damaged_copy_in_the_cache_is_replaced(artifact, tmp_path):
    packed = bundle.pack(artifact)
    where = bundle.unpack(packed, cache=tmp_path)
    urdf = next(where.rglob("*.urdf"))
    urdf.write_text(urdf.read_text().replace("<robot", "<robot ", 1))
    assert bundle.unpack(packed, cache=tmp_path) == where
    assert urdf.read_bytes() == packed["files"][urdf.relative_to(where).as_posix()]


def test_a_tampered_bundle_is_refused(artifact, tmp_path):
    packed = bundle.pack(artifact)
    name = next(n for n in packed["files"] if n.endswith(".urdf"))
    packed["files"][name] = packed["files"][name].replace(b"<robot", b"<robot ", 1)
    with pytest.raises(Exception, match="damaged artifact: .*files differ from what was compiled"):
        bundle.unpack(packed, cache=tmp_path)
    assert not (tmp_path / "jobs" / packed["content_hash"]).exists() and list((tmp_path / "jobs").iterdir()) == []


def test_a_worker_with_other_code_refuses_naming_both(artifact, tmp_path):
    packed = bundle.pack(artifact)
    packed.update(version="0.0.9", source_hash="f" * 64)
    with pytest.raises(UsageError) as err:
        bundle.unpack(packed, cache=tmp_path)
    ours = bundle.source_hash()[:12]
    assert str(err.value) == (
        f"this worker's assistive-compiler 0.1.0 (source {ours}) differs from the driver's 0.0.9 (source ffffffffffff): the "
        f"compiled task {packed['content_hash'][:12]} (feeding, jaco) could run differently here; install the same "
        "assistive-compiler on every machine of the cluster"
    )

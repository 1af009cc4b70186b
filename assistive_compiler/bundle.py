"""A compiled task that travels with a job: packed on the driver, unpacked on each worker.

Nothing of the driver's file system is needed where a job's envs run (another machine of a Ray
cluster, a process in its own mount namespace): :func:`pack` reads an artifact directory into a
plain dict of bytes (a compiled task is ~150 kB), which goes into the job's env config; on the
worker :func:`unpack` writes it into that machine's own cache, keyed by the artifact's content
hash, checks it (the manifest's content hash over every file) and returns the directory. A worker
whose installed assistive-compiler differs from the driver's — its version or the hash of its
source — refuses with a message naming both: the same artifact can run differently on other code.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
from functools import cache
from pathlib import Path

from .errors import UsageError
from .version import __version__

PACKAGE_DIR = Path(__file__).resolve().parent
FORMAT = 1


@cache
def source_hash() -> str:
    """sha256 of the installed package's Python source (paths relative to the package, so two
    machines with the same code agree wherever it is installed)."""
    h = hashlib.sha256()
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        h.update(path.relative_to(PACKAGE_DIR).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def pack(artifact_dir: str | Path) -> dict:
    """The artifact at ``artifact_dir`` as a picklable dict: every file's bytes by relative path,
    its content hash, and the driver's package version and source hash."""
    from .artifact import Manifest

    root = Path(artifact_dir)
    manifest = Manifest.read(root, verify=True)
    files = {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}
    return {
        "format": FORMAT,
        "content_hash": manifest.content_hash,
        "task": manifest.task,
        "robot": manifest.robot_name,
        "version": __version__,
        "source_hash": source_hash(),
        "files": files,
    }


def check_same_package(bundle: dict) -> None:
    """Refuse a bundle packed by another assistive-compiler (version or source)."""
    ours, theirs = (__version__, source_hash()), (bundle["version"], bundle["source_hash"])
    if ours != theirs:
        raise UsageError(
            f"this worker's assistive-compiler {ours[0]} (source {ours[1][:12]}) differs from the driver's {theirs[0]} "
            f"(source {theirs[1][:12]}): the compiled task {bundle['content_hash'][:12]} ({bundle['task']}, {bundle['robot']}) "
            "could run differently here; install the same assistive-compiler on every machine of the cluster"
        )


def unpack(bundle: dict, cache: str | Path | None = None) -> Path:
    """The bundle's artifact in this machine's cache (``<cache>/jobs/<content hash>``), written
    once (atomically: a concurrent worker sees a complete directory or none) and checked."""
    from .artifact import Manifest
    from .registration import cache_dir

    if bundle.get("format") != FORMAT:
        raise UsageError(
            f"a compiled-task bundle of format {bundle.get('format')} (this assistive-compiler reads format {FORMAT})"
        )
    check_same_package(bundle)
    root = Path(cache) if cache is not None else cache_dir()
    target = root / "jobs" / bundle["content_hash"]
    if target.is_dir() and _intact(target, bundle["content_hash"]):
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{bundle['content_hash'][:12]}-", dir=target.parent))
    try:
        for rel, data in bundle["files"].items():
            path = tmp / rel
            if ".." in Path(rel).parts or Path(rel).is_absolute():
                raise UsageError(f"a compiled-task bundle names a file outside its artifact: {rel}")
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        manifest = Manifest.read(tmp, verify=True)
        if manifest.content_hash != bundle["content_hash"]:
            raise UsageError(
                f"a compiled-task bundle says content hash {bundle['content_hash'][:12]} but holds "
                f"{manifest.content_hash[:12]}"
            )
        if target.is_dir():  # a damaged earlier copy: replace it
            shutil.rmtree(target, ignore_errors=True)
        try:
            os.rename(tmp, target)
        except OSError:  # another worker put it there first
            if not _intact(target, bundle["content_hash"]):
                raise
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return target


def _intact(directory: Path, content_hash: str) -> bool:
    from .artifact import Manifest
    from .errors import SpecError

    try:
        return Manifest.read(directory, verify=True).content_hash == content_hash
    except SpecError:
        return False

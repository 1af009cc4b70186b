"""The compiler's driver: a spec file → an artifact directory (URDFs + ``manifest.json``).

:func:`compile_task` loads the spec, returns the cached artifact when its inputs are unchanged,
else resolves the task and runs the stages (:func:`build`) into a temporary sibling directory
that replaces the output only when complete, so a failed compile leaves nothing half-written.
The manifest records a hash of every input (:func:`input_hash`; a later compile of unchanged
inputs is a cache hit) and a hash of the output bytes. The same inputs always give
byte-identical output. The stages, in order, are listed in :mod:`assistive_compiler.compile`.
"""

from __future__ import annotations

import errno
import hashlib
import os
import shutil
import tempfile
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from ..artifact import Manifest
from ..library import Library
from ..paths import templates_dir
from ..resolve import ResolvedTask, resolve
from ..spec.load import LoadedSpec, load_spec
from ..version import __version__
from .emit import emit_people, emit_props
from .person import finish_person, merge_people
from .placement import precompute
from .placement.settle_person import settle_people
from .robot import merge_robot, weld_tools
from .task import arm_limits_path

PACKAGE_DIR = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class CompileResult:
    """What a compile produced and whether it came from the cache."""

    out_dir: Path
    manifest: Manifest
    cache_hit: bool
    seconds: float


def default_out_dir(task: str, robot: str) -> Path:
    return Path("generated") / f"{task}-{robot}"


def input_hash(loaded: LoadedSpec, robot: str, library: Library) -> str:
    """sha256 over every input that can change the output, known before resolving: the spec files,
    every part file of the library, every template (ours and those beside user libraries), the
    compiler's own source, and the robot. Conservative — editing any part invalidates every
    artifact — so a cache hit never needs resolution."""
    h = hashlib.sha256(f"assistive-compiler {__version__} robot={robot}\n".encode())
    files = list(loaded.files)
    if loaded.spec.person.control.arm_limits not in ("none", "analytic") and arm_limits_path(loaded).is_file():
        files.append(arm_limits_path(loaded))  # a user's arm-limit network
    for root in library.roots:
        files += sorted(root.rglob("*.yaml")) + sorted((root.parent / "templates").rglob("*.xacro"))
    files += sorted(templates_dir().rglob("*.xacro")) + sorted(PACKAGE_DIR.rglob("*.py"))
    for path in files:
        h.update(str(path).encode() + b"\0" + Path(path).read_bytes() + b"\0")
    return h.hexdigest()


def build(rt: ResolvedTask, out_tmp: Path, lib: Library) -> Manifest:
    """Run the stages for ``rt`` into ``out_tmp``; returns the manifest (without hashes)."""
    scene = emit_props(rt, out_tmp / "urdf", lib)  # 1. robot (welded), furniture, tools: rendered, linted, written
    settled = settle_people(rt, scene)  # 2. a supine person dropped onto the furniture (else nothing)
    emit_people(rt, scene, settled)  # 3. each person variant, its static joints baked at the posture
    manifest = precompute(rt, scene, out_tmp)  # 4. base poses, start configurations, particles, garments
    pairs = merge_people(rt, scene)  # 5. each person's static links merged; self-collision pairs
    manifest = weld_tools(manifest, scene)  # 6. tools nothing with weight presses on welded in,
    merge_robot(manifest, scene)  # and the robot's links the manifest does not name merged
    return finish_person(rt, manifest, out_tmp, pairs)  # 7. pairs apart at rest, arm-limit model


def compile_task(
    spec_path: str | Path,
    robot: str | None = None,
    out_dir: str | Path | None = None,
    *,
    library: Library | Iterable[str | Path] | None = None,
    force: bool = False,
) -> CompileResult:
    """Compile the spec at ``spec_path`` for ``robot`` into ``out_dir`` (default generated/<task>-<robot>).

    ``library``: a :class:`Library`, or extra library directories searched before
    ``$ASSISTIVE_COMPILER_LIBRARY``, the spec's own library and the shipped parts
    (:meth:`Library.for_spec`).

    Raises :class:`SpecError` for bad input; leaves ``out_dir`` untouched unless it succeeds.
    """
    t0 = time.perf_counter()
    loaded: LoadedSpec = load_spec(spec_path)
    if not isinstance(library, Library):
        library = Library.for_spec(loaded.path, library or ())
    robot = robot or loaded.spec.robot.default
    out = Path(out_dir) if out_dir else default_out_dir(loaded.spec.name, robot)
    ihash = input_hash(loaded, robot, library)
    manifest_path = out / "manifest.json"
    if not force and manifest_path.is_file():
        try:
            existing = Manifest.read(out)
        except Exception:
            existing = None
        # A cut or edited file in the cache (damage) is recompiled, never loaded.
        if existing is not None and existing.input_hash == ihash and existing.damage(out) is None:
            return CompileResult(out, existing, True, time.perf_counter() - t0)

    rt = resolve(loaded, robot, library)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-", dir=out.parent))
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it private; the artifact is an ordinary directory
    try:
        manifest = build(rt, tmp, library).model_copy(update={"input_hash": ihash})
        manifest = manifest.model_copy(update={"content_hash": manifest.hash_of(tmp)})
        text = manifest.to_json()
        (tmp / "manifest.json").write_text(text)
        _replace_dir(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    # The manifest as every later load sees it, parsed from the text just written: the file sorts its
    # keys, and the runtime walks some of its dicts in order (a fresh compile's in-memory order gave
    # Dressing a different episode).
    return CompileResult(out, Manifest.model_validate_json(text), False, time.perf_counter() - t0)


def _replace_dir(new: Path, out: Path) -> None:
    """Move ``new`` to ``out``, replacing any previous ``out`` only once ``new`` is complete."""
    old = None
    if out.exists():
        old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-", dir=out.parent))
        os.rmdir(old)
        os.rename(out, old)
    try:
        os.rename(new, out)
    except OSError as exc:
        # Another process (a vector env's workers making the same id at once, parallel tests) put
        # the same compile there first: keep its result (the same inputs give the same files).
        if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST) or not (out / "manifest.json").is_file():
            raise
        shutil.rmtree(new, ignore_errors=True)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)

"""Independent validators for written URDF files, used by the tests and by
``assistive-compiler compile --strict``.

Each function takes the path of a URDF file on disk and returns a list of human-readable
problem lines; an empty list means the validator accepted the file.

- `check_with_urdfdom`: urdfdom's ``check_urdf`` executable (PyPI package ``cmeel-urdfdom``);
- `check_with_yourdfpy`: ``yourdfpy.URDF.load`` with a scene graph, then ``validate()``;
- `pybullet_load_warnings`: what PyBullet's C code prints while ``loadURDF`` reads the file.

Heavy libraries (yourdfpy, pybullet) are imported inside the functions that use them.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

from ..bullet import connect

__all__ = [
    "check_with_urdfdom",
    "check_with_yourdfpy",
    "find_check_urdf",
    "pybullet_load_warnings",
]

_CHECK_URDF_TIMEOUT_S = 30.0


def _existing_file(path: str | os.PathLike[str]) -> Path:
    file = Path(path)
    if not file.is_file():
        raise FileNotFoundError(f"URDF file not found: {file}")
    return file


def find_check_urdf() -> str:
    """Path of urdfdom's ``check_urdf``: next to ``sys.executable`` first, then on PATH."""
    beside = Path(sys.executable).parent / "check_urdf"
    if beside.is_file() and os.access(beside, os.X_OK):
        return str(beside)
    on_path = shutil.which("check_urdf")
    if on_path:
        return on_path
    raise FileNotFoundError(
        "urdfdom's check_urdf executable was not found next to "
        f"{sys.executable} or on PATH; install it with `pip install cmeel-urdfdom`"
    )


def check_with_urdfdom(path: str | os.PathLike[str]) -> list[str]:
    """Run ``check_urdf`` on ``path``; return its error and warning lines (empty = pass).

    ``check_urdf`` does not always exit non-zero when it reports an error (an unparseable
    ``<visual>`` is dropped with an "Error:" line and exit status 0), so the output is read as
    well as the exit status.
    """
    file = _existing_file(path)
    exe = find_check_urdf()
    try:
        result = subprocess.run(
            [exe, str(file)],
            capture_output=True,
            text=True,
            errors="replace",
            timeout=_CHECK_URDF_TIMEOUT_S,
            check=False,
        )
    except subprocess.TimeoutExpired:
        return [f"check_urdf did not finish within {_CHECK_URDF_TIMEOUT_S:g} s"]
    problems = []
    for line in (result.stderr + "\n" + result.stdout).splitlines():
        text = line.strip()
        if re.match(r"(error|warning)\b", text, flags=re.IGNORECASE):
            problems.append(text)
    if result.returncode != 0 and not problems:
        problems.append(f"check_urdf exited with status {result.returncode}")
    return problems


class _ListHandler(logging.Handler):
    def __init__(self) -> None:
        super().__init__(level=logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self.messages.append(f"{record.levelname.lower()}: {record.getMessage()}")
        except Exception:  # a malformed log call must not break the check
            self.messages.append(f"{record.levelname.lower()}: {record.msg!r}")


def check_with_yourdfpy(path: str | os.PathLike[str]) -> list[str]:
    """Load ``path`` with yourdfpy (scene graph built, meshes not loaded) and validate it.

    Returns yourdfpy's validation errors, any exception raised while loading, and the
    warnings yourdfpy logs while loading (e.g. a link not connected by joints); empty = pass.
    """
    import yourdfpy

    file = _existing_file(path)
    logger = logging.getLogger("yourdfpy")
    handler = _ListHandler()
    old_level = logger.level
    logger.addHandler(handler)
    if logger.getEffectiveLevel() > logging.WARNING:
        logger.setLevel(logging.WARNING)
    problems: list[str] = []
    try:
        try:
            urdf = yourdfpy.URDF.load(str(file), build_scene_graph=True, load_meshes=False)
        except Exception as exc:  # yourdfpy raises many kinds (ValueError, KeyError, ...)
            problems.append(f"load failed: {_describe(exc)}")
        else:
            try:
                if not urdf.validate():
                    problems.extend(_describe(err) for err in urdf.errors)
            except Exception as exc:
                problems.append(f"validate failed: {_describe(exc)}")
    finally:
        logger.removeHandler(handler)
        logger.setLevel(old_level)
    return handler.messages + problems


def _describe(err: BaseException) -> str:
    text = str(err)
    name = type(err).__name__
    return text if text.startswith(name) else f"{name}: {text}"


@contextlib.contextmanager
def captured_c_output() -> Iterator[list[str]]:
    """Capture what C code prints to fd 1 and fd 2 (Bullet prints its warnings there, past
    Python's sys.stdout). Yields a list that holds the captured text once the block exits; the
    descriptors are restored even on exceptions. fd 1/2 are process-wide: don't overlap it with
    other threads' output."""
    result: list[str] = []
    sys.stdout.flush()
    sys.stderr.flush()
    _c_fflush()
    with tempfile.TemporaryFile(mode="w+b") as capture:
        saved_out = os.dup(1)
        try:
            saved_err = os.dup(2)
        except OSError:
            os.close(saved_out)
            raise
        try:
            os.dup2(capture.fileno(), 1)
            os.dup2(capture.fileno(), 2)
            yield result
        finally:
            _c_fflush()
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved_out, 1)
            os.dup2(saved_err, 2)
            os.close(saved_out)
            os.close(saved_err)
            capture.seek(0)
            result.append(capture.read().decode("utf-8", errors="replace"))


def _c_fflush() -> None:
    """Flush C stdio buffers, so that text the C library printed reaches its fd now."""
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):
        pass


# PyBullet prints "b3Warning[file,line]:\n" or "b3Error[file,line]:\n" and then the message,
# often without a newline before the next header.
_B3_HEADER = re.compile(r"b3(Warning|Error|Printf)\[[^\]\n]*\]:[ \t]*\n?")
_LOOKS_BAD = re.compile(r"warn|error|fail", re.IGNORECASE)


def _warning_lines(text: str) -> list[str]:
    lines: list[str] = []
    pieces = _B3_HEADER.split(text)
    # pieces = [before, kind1, body1, kind2, body2, ...]
    for line in pieces[0].splitlines():
        if _LOOKS_BAD.search(line):
            lines.append(line.strip())
    previous_kind = None
    for kind, body in zip(pieces[1::2], pieces[2::2]):
        body = " ".join(body.split())
        if kind not in ("Warning", "Error"):
            if _LOOKS_BAD.search(body):
                lines.append(body)
            previous_kind = None
            continue
        if body and " " not in body and previous_kind == kind and lines:
            # PyBullet reports a message and then, as a second record, the name it is about
            # ("No inertial data for link, ..." then "forearm"): join them.
            lines[-1] = f"{lines[-1]} [{body}]"
            previous_kind = None
            continue
        lines.append(f"b3{kind}: {body}" if body else f"b3{kind}")
        previous_kind = kind
    return lines


def pybullet_load_warnings(path: str | os.PathLike[str], *, use_fixed_base: bool = True) -> list[str]:
    """Load ``path`` into a fresh DIRECT pybullet client and return the warning/error lines
    the C library printed to stdout/stderr meanwhile (empty = loaded silently).

    A load that fails outright adds a ``"loadURDF failed: ..."`` line. A file whose links do
    not form one tree (several roots, a link with two parent joints, a cycle) is not loaded at
    all, because PyBullet 3.2.7 crashes the whole process on it (segmentation fault); its
    structure problems are returned instead.

    File descriptors 1 and 2 are process-wide: do not run this concurrently with other
    threads that write to stdout/stderr and expect to see their output.
    """
    import pybullet

    from .lint import pybullet_crash_risks

    file = _existing_file(path)
    risks = pybullet_crash_risks(file.read_text(encoding="utf-8", errors="replace"))
    if risks:
        return [
            f"error: not loaded (pybullet crashes on links that do not form one tree): "
            f"{problem.element}: {problem.message}"
            for problem in risks
        ]
    load_failure: str | None = None
    with captured_c_output() as printed:
        client = connect()
        if client < 0:
            load_failure = "pybullet.connect(DIRECT) failed"
        else:
            try:
                pybullet.loadURDF(str(file), useFixedBase=use_fixed_base, physicsClientId=client)
            except pybullet.error as exc:
                load_failure = f"loadURDF failed: {exc}"
            finally:
                pybullet.disconnect(physicsClientId=client)
    text = printed[0]
    lines = _warning_lines(text)
    if load_failure is not None:
        lines.append(load_failure)
    return lines

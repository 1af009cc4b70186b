"""``bench``'s one-env memory figure (``peak_rss_mb_one_env``) is the peak of a process that builds
one env and steps it, not the high-water mark of the process that runs bench: Linux carries
``getrusage``'s ``ru_maxrss`` over fork and exec, so the figure once read about 1,160 MB for
Feeding x Jaco where such a process peaks near 100 MB (issue 46)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from assistive_compiler.cli.bench import _CHILD, measure_process

BALLAST_MB = 400

pytestmark = pytest.mark.skipif(
    not Path("/proc/self/status").is_file(), reason="bench reads a process's peak from /proc/self/status"
)

# Runs argv[1:] as a child forked from this small interpreter and prints the child's getrusage peak
# (MB): the child starts from this launcher's high-water mark (about 10 MB), not the test's.
_LAUNCHER = """
import os, sys
pid = os.fork()
if pid == 0:
    os.execv(sys.executable, [sys.executable, *sys.argv[1:]])
_, status, usage = os.wait4(pid, 0)
assert os.waitstatus_to_exitcode(status) == 0
print(usage.ru_maxrss / 1024)
"""


def _standalone_peak_mb(artifact: Path) -> float:
    """Peak RSS (MB) of a fresh process that builds ``artifact``'s env and steps it as bench's child
    does, read another way than bench reads it (the kernel's rusage of a process whose parent is small)."""
    out = subprocess.run(
        [sys.executable, "-c", _LAUNCHER, "-c", _CHILD, str(artifact)], capture_output=True, text=True, check=True
    )
    return float(out.stdout.split()[-1])


def _own_high_water_mb() -> float:
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) / 1024 for line in f if line.startswith("VmHWM:"))


def test_bench_one_env_peak_is_that_process_own_and_not_its_parents(artifact):
    standalone = _standalone_peak_mb(artifact)
    ballast = bytearray(b"\1") * (BALLAST_MB << 20)  # every page written: this process's high-water mark rises
    try:
        assert _own_high_water_mb() > BALLAST_MB
        peak = measure_process(artifact)["peak_rss_mb"]
    finally:
        del ballast
    assert peak == pytest.approx(standalone, rel=0.10)
    assert peak < BALLAST_MB / 2, f"{peak:.0f} MB: the parent's high-water mark, not the env's"

"""``train --json``: stdout holds the summary alone, whatever else the process writes to its
stdout afterwards — Ray forwards cluster messages (e.g. "raylet ... died") from its threads and at
interpreter exit, after the summary is printed (a CI run failed on one)."""

import json
import subprocess
import sys

PROGRAM = """
import atexit, os, sys
from assistive_compiler.cli.train import _stdout_for_the_summary_alone

print("training prints this")
summary_out = _stdout_for_the_summary_alone()
print("a line from training after the switch")
os.write(1, b"a forwarded cluster message written to file descriptor 1\\n")
atexit.register(lambda: print("a message at interpreter exit"))
print('{"steps": 1400}', file=summary_out, flush=True)
"""


def test_everything_written_to_stdout_after_the_switch_goes_to_stderr():
    done = subprocess.run([sys.executable, "-c", PROGRAM], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    before, summary = done.stdout.splitlines()
    assert before == "training prints this" and json.loads(summary) == {"steps": 1400}
    assert sorted(done.stderr.splitlines()) == [  # sorted: print is buffered, os.write is not
        "a forwarded cluster message written to file descriptor 1",
        "a line from training after the switch",
        "a message at interpreter exit",
    ]

"""The CLI's presentation: ``compare``'s table (aligned columns, success rates to two decimals, the
JLWKI explained), progress on stderr, and that ``rich`` stays a CLI-only import."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from assistive_compiler.cli import main
from assistive_compiler.cli.compare import COLUMNS, print_comparison

TASKS = Path(__file__).resolve().parents[2] / "specs" / "tasks"
NUMERIC = ("goals_reached", "jlwki", "compile_s", "success", "return")


def _table(out: str) -> tuple[str, list[str]]:
    """The header line of a table and its row lines (the line after the header is its rule)."""
    lines = out.splitlines()
    at = next(i for i, line in enumerate(lines) if line.split()[:2] == ["robot", "placement"])
    assert set(lines[at + 1]) == {"─"}
    rows = []
    for line in lines[at + 2 :]:
        if not line.strip() or line.startswith("jlwki:"):
            break
        rows.append(line)
    return lines[at], rows


def _assert_aligned(header: str, rows: list[str]) -> None:
    """Text columns start where their header starts; number columns end where their header ends."""
    for row in rows:
        assert row.startswith(row.split()[0]) and header.startswith("robot")
        for name in NUMERIC:
            end = header.index(name) + len(name)
            assert row[end - 1] != " " and (len(row) == end or row[end] == " "), (name, row)


@pytest.mark.slow
def test_compare_prints_an_aligned_rounded_table_and_explains_jlwki(capsys):
    """A real comparison of a mounted robot (Jaco) and a base-searching one (PR2) on Scratch Itch."""
    rc = main(["compare", str(TASKS / "scratch_itch.yaml"), "--robots", "jaco,pr2", "--episodes", "1"])
    assert rc == 0
    captured = capsys.readouterr()
    header, rows = _table(captured.out)
    assert header.split() == list(COLUMNS)
    assert [r.split()[0] for r in rows] == ["jaco", "pr2"]
    _assert_aligned(header, rows)
    success_at = header.index("success")
    for row in rows:
        assert re.fullmatch(r"[01]\.\d\d", row[success_at : success_at + len("success")].strip())
    assert "mounted on wheelchair" in rows[0] and "base search" in rows[1]
    assert re.search(r"\d/\d+\s+\d+\.\d{3}\s", rows[1])  # goals reached, then the JLWKI to 3 decimals
    assert "jlwki: joint-limit-weighted kinematic isotropy" in captured.out
    # Progress on stderr, one line per robot finished: stdout holds only the report.
    assert re.search(
        r"^\[1/2\] jaco: compiled in [\d.]+ s \(mounted on wheelchair\), success [01]\.\d\d$", captured.err, re.M
    )
    assert re.search(r"^\[2/2\] pr2: compiled in [\d.]+ s \(base search\)", captured.err, re.M)


def test_compare_table_rounds_success_and_lists_compile_failures_below(capsys):
    rows = [
        {
            "robot": "pr2",
            "compile_s": 8.16,
            "placement": "base search",
            "goals_reached": "3/4",
            "jlwki": 1.234,
            "success": 1 / 3,
            "return": -12.5,
        },
        {"robot": "sawyer", "error": "robot 'sawyer' reaches the mouth from none of 50 sampled base poses"},
        {"robot": "jaco", "compile_s": 2.5, "placement": "mounted on wheelchair", "success": 1.0, "return": 118.2},
    ]
    print_comparison(rows)
    out = capsys.readouterr().out
    header, table = _table(out)
    assert [r.split()[0] for r in table] == ["pr2", "sawyer", "jaco"]
    _assert_aligned(header, [table[0], table[2]])
    assert table[0].split() == ["pr2", "base", "search", "3/4", "1.234", "8.16", "0.33", "-12.5"]
    assert table[1].split() == ["sawyer", "failed", "to", "compile", "-", "-", "-", "-", "-"]
    assert table[2].split() == ["jaco", "mounted", "on", "wheelchair", "-", "-", "2.5", "1.00", "118.2"]
    assert "0.333" not in out
    assert (
        out.rstrip().splitlines()[-1]
        == "sawyer: failed to compile: robot 'sawyer' reaches the mouth from none of 50 sampled base poses"
    )


def test_run_json_stays_pure_json_with_progress_on_stderr(tmp_path, capsys):
    spec = TASKS / "feeding.yaml"
    rc = main(
        [
            "run",
            str(spec),
            "--robot",
            "jaco",
            "--policy",
            "zero",
            "--episodes",
            "1",
            "--json",
            "--out-dir",
            str(tmp_path / "art"),
        ]
    )
    assert rc == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert set(report) == {"task", "robot", "policy", "term_weights", "episodes", "success_rate", "mean_return"}
    assert re.search(
        r"^\[1/1\] episode 0 \(seed 0\): return -?[\d.]+, success no; 0/1 successful so far$", captured.err, re.M
    )


@pytest.mark.parametrize("module", ["assistive_compiler", "assistive_compiler.cli"])
def test_rich_is_imported_only_when_the_cli_prints(module):
    """``import assistive_compiler`` (and building the CLI's parser, and parsing a ``train``
    command line) loads neither rich nor the training libraries."""
    code = f"import {module}, sys\n"
    if module == "assistive_compiler.cli":
        code += "assistive_compiler.cli.build_parser().parse_args(['train', 'x.yaml', '--config', 'ppo_quick'])\n"
    code += (
        "heavy = [m for m in ('rich', 'torch', 'ray', 'stable_baselines3', 'jax', 'sbx', 'matplotlib', 'tensorboard') if m in sys.modules]\n"
        "assert not heavy, heavy\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_every_command_group_registers_its_commands():
    from assistive_compiler.cli import COMMAND_MODULES, build_parser

    sub = next(a for a in build_parser()._actions if a.dest == "command")
    assert set(sub.choices) == {
        "validate",
        "compile",
        "list",
        "schema",
        "run",
        "demo",
        "render",
        "render-person",
        "bench",
        "compare",
        "view",
        "collect",
        "train",
        "evaluate",
        "table",
        "export",
        "results",
        "person-reference",
        "describe",
    }
    assert all(callable(m.add_commands) for m in COMMAND_MODULES)


def test_the_artifact_directory_is_out_dir_in_every_command_and_run_s_old_out_still_works(capsys):
    """Issue 48, defect 7: --out is what a command writes (render's picture, compile's artifact);
    the artifact directory a command compiles into on the way is --out-dir everywhere, and the
    older spelling --out of run, view and compare still works, with a note."""
    from assistive_compiler.cli import build_parser

    parser = build_parser()
    needs = {"render": ["--out", "x.png"], "compare": ["--robots", "jaco"]}
    for command in ("run", "view", "compare", "render", "describe"):
        args = parser.parse_args([command, "t.yaml", "--out-dir", "build/t", *needs.get(command, [])])
        assert (args.out_dir if command in ("render", "describe") else args.out) == "build/t", command
    assert parser.parse_args(["compile", "t.yaml", "--out-dir", "build/t"]).out == "build/t"
    assert parser.parse_args(["compile", "t.yaml", "--out", "build/t"]).out == "build/t"
    assert capsys.readouterr().err == ""
    for command in ("run", "view", "compare"):
        assert parser.parse_args([command, "t.yaml", "--out", "build/t", *needs.get(command, [])]).out == "build/t"
        assert capsys.readouterr().err == (
            f"assistive-compiler {command}: --out here is the older spelling of --out-dir (the artifact directory, "
            "as in render, where --out is the picture); it still works\n"
        )

"""Shipped tasks are named from any directory, as a wheel install has them: by name (``feeding``),
as ``shipped:tasks/feeding.yaml``, or by Gymnasium id; ``list`` shows those names, not the
installed files' paths (issue 48, defect 9)."""

from __future__ import annotations

import pytest

from assistive_compiler.cli import main
from assistive_compiler.paths import specs_dir
from assistive_compiler.spec.load import load_spec, spec_path

TASKS = "arm_manipulation, bed_bathing, dressing, drinking, feeding, scratch_itch"


@pytest.fixture
def elsewhere(tmp_path, monkeypatch):
    """An empty working directory, with no specs/ in it."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_a_shipped_task_is_named_by_its_name_or_shipped_path(elsewhere):
    feeding = specs_dir() / "tasks" / "feeding.yaml"
    assert spec_path("feeding") == feeding and spec_path("shipped:tasks/feeding.yaml") == feeding
    assert spec_path("shipped:feeding") == feeding and spec_path("shipped:examples/reach.yaml").is_file()
    assert load_spec("feeding").path == feeding.resolve()
    (elsewhere / "feeding").write_text("name: mine\n")  # a file of that name here wins
    assert spec_path("feeding").resolve() == elsewhere / "feeding"


def test_validate_by_name_and_by_shipped_path_from_an_empty_directory(elsewhere, capsys):
    assert main(["validate", "feeding", "shipped:tasks/drinking.yaml"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out == [
        "feeding: ok (task 'feeding', robots: jaco, pr2, baxter, sawyer, panda, stretch)",
        "shipped:tasks/drinking.yaml: ok (task 'drinking', robots: pr2, jaco, baxter, sawyer, panda, stretch)",
    ]


def test_an_unknown_name_says_how_shipped_tasks_are_named(elsewhere, capsys):
    assert main(["validate", "feedin"]) == 2
    assert capsys.readouterr().err.strip() == (
        f"feedin:1:1: file not found; a shipped task is named by its name ({TASKS}) or as "
        "shipped:tasks/<name>.yaml, from any directory (did you mean 'feeding'?)"
    )
    assert main(["run", "shipped:tasks/feedin.yaml", "--robot", "jaco"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("shipped:tasks/<name>.yaml, from any directory (did you mean 'feeding'?)"), err
    assert err.startswith(f"{specs_dir() / 'tasks' / 'feedin.yaml'}:1:1: file not found; ")


def test_run_by_name_and_by_gymnasium_id(elsewhere, artifact, capsys):
    assert main(["run", "feeding", "--robot", "jaco", "--episodes", "1", "--out-dir", str(artifact), "--quiet"]) == 0
    by_name = capsys.readouterr().out
    assert by_name.startswith("assistive_compiler/FeedingJaco-v1  policy=scripted  episodes=1  seed=0")
    assert main(["run", "FeedingJaco-v1", "--episodes", "1", "--out-dir", str(artifact), "--quiet"]) == 0
    assert capsys.readouterr().out == by_name  # the same task, robot and episode
    id_ = "assistive_compiler/FeedingJaco-v1"
    assert main(["run", id_, "--robot", "panda", "--episodes", "1", "--out-dir", str(artifact)]) == 2
    assert capsys.readouterr().err.strip() == (
        f"error: {id_} is the task for robot 'jaco', but --robot is 'panda'; give one of them"
    )


def test_list_names_tasks_by_name_not_by_installed_path(elsewhere, capsys):
    assert main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith(
        "6 tasks x 6 robots (baxter, jaco, panda, pr2, sawyer, stretch). Name a task by its name"
    )
    assert "(assistive-compiler run arm_manipulation --robot pr2)" in lines[0]
    assert any(" feeding " in line and "assistive_compiler/Feeding" in line for line in lines)
    assert lines[-1] == f"(the spec files, to read or copy: {specs_dir() / 'tasks'})"
    assert not any(".yaml" in line for line in lines[1:-1])  # no file is the way to name a task

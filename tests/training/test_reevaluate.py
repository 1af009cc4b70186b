"""Shipped figures are the current code's: ``results`` says which shipped policies were evaluated
on another compile of their task than the current code's, and ``results --reevaluate`` measures
them again there (the weights unchanged, the replaced evaluation kept in short)."""

from __future__ import annotations

import json
import shutil

import pytest

import assistive_compiler.policies.pretrained as pretrained
from assistive_compiler.cli import main
from assistive_compiler.policies.pretrained import shipped_info
from assistive_compiler.training.trained.reevaluate import stale_figures

NAME = "scratch_itch-pr2"  # sampled actions too (it has its log-std); 200-step episodes
EPISODES = 3
OLDER = "0" * 64


@pytest.fixture
def shipped_elsewhere(tmp_path, monkeypatch):
    """A copy of one shipped policy in a pretrained folder of its own, as if trained and evaluated on
    an older compile of its task, and evaluated on its first EPISODES seeds only (for time)."""
    folder = tmp_path / "pretrained" / NAME
    shutil.copytree(pretrained.pretrained_folder(NAME), folder)
    record = json.loads((folder / "policy.json").read_text())
    for key in ("evaluation", "evaluation_sampled"):
        record[key] = {
            **record[key],
            "episodes": EPISODES,
            "returns": record[key]["returns"][:EPISODES],
            "successes": record[key]["successes"][:EPISODES],
        }
    (folder / "policy.json").write_text(json.dumps({**record, "content_hash": OLDER}, indent=1) + "\n")
    shipped = shipped_info(NAME)
    monkeypatch.setattr(pretrained, "pretrained_dir", lambda: tmp_path / "pretrained")
    return shipped


def test_results_names_the_stale_figures_and_reevaluate_measures_them_on_todays_compile(
    shipped_elsewhere, tmp_path, capsys
):
    shipped = shipped_elsewhere
    now = shipped["content_hash"]  # the shipped policy was evaluated on today's compile
    assert [(s.name, s.evaluated_on, s.compiled_now) for s in stale_figures([NAME])] == [(NAME, OLDER, now)]

    doc = tmp_path / "results.md"
    assert main(["results", "--no-pictures", "--out", str(doc)]) == 0
    err = capsys.readouterr().err
    assert (
        f"1 shipped policy was evaluated on another compile of the task than the current code's, so its figures are "
        f"not today's: {NAME} (measured on 000000000000, the task compiles to {now[:12]} now). "
        "`assistive-compiler results --reevaluate` measures them again." in err
    )

    assert main(["results", "--reevaluate", "--no-pictures", "--out", str(doc)]) == 0
    out, err = capsys.readouterr()
    assert f"re-evaluated {NAME} on the task compiled now ({now[:12]})" in out
    assert f"python -m tests.pretrained_regression --write --from-evaluation {NAME}" in out
    assert "measures them again" not in err and stale_figures([NAME]) == []

    record = shipped_info(NAME)
    assert record["content_hash"] == OLDER and record["evaluated_on_content_hash"] == now  # trained on / measured on
    for key in ("evaluation", "evaluation_sampled"):  # the same seeds on the same compile: the same episodes
        assert record[key]["returns"] == shipped[key]["returns"][:EPISODES], key
        assert record[key]["successes"] == shipped[key]["successes"][:EPISODES], key
    assert record["regression"]["episodes"] == EPISODES
    assert record["earlier_evaluations"] == [
        {
            "content_hash": OLDER,
            "success_rate": shipped["evaluation"]["success_rate"],
            "mean_return": round(shipped["evaluation"]["mean_return"], 3),
            "success_rate_sampled": shipped["evaluation_sampled"]["success_rate"],
            "mean_return_sampled": round(shipped["evaluation_sampled"]["mean_return"], 3),
        }
    ]
    assert (
        f"Trained on the compiled task 000000000000; evaluated on {now[:12]}, the task as the code compiled it on "
        f"{record['evaluated']}" in doc.read_text()
    )


def test_reevaluating_an_unknown_policy_is_a_clear_error(shipped_elsewhere, tmp_path, capsys):
    assert main(["results", "--reevaluate", "scratch_itch-pr3", "--no-pictures", "--out", str(tmp_path / "r.md")]) == 2
    assert capsys.readouterr().err.strip() == (
        f"error: results --reevaluate: no shipped policy scratch_itch-pr3; shipped: '{NAME}' (did you mean '{NAME}'?)"
    )

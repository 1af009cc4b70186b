"""docs/person.md is the person model as the code renders it (links, frames, joints, limits)."""

from __future__ import annotations

from pathlib import Path

from assistive_compiler.cli import main
from assistive_compiler.library import Library
from assistive_compiler.person.reference_page import person_reference_markdown
from assistive_compiler.urdf import urdf_info

PAGE = Path(__file__).resolve().parents[2] / "docs" / "person.md"


def test_the_person_page_is_what_the_code_renders():
    assert PAGE.read_text() == person_reference_markdown(), (
        "docs/person.md is stale: run 'assistive-compiler person-reference'"
    )


def test_the_page_lists_every_link_and_joint_with_the_models_limits():
    info = urdf_info(Library().person_urdf("male_50th"))
    text = PAGE.read_text()
    assert len(info.links) == 43
    for link in info.links:
        assert f"| `{link}` |" in text
    elbow = info.joints["right_elbow"]
    assert (
        f"| `right_elbow` | revolute | x | `right_shoulder` → `right_elbow_link` | [{round(elbow.lower * 57.29578)}, {round(elbow.upper * 57.29578)}] |"
        in text
    )
    # The upper arm hangs 27.9 cm from the shoulder to the elbow joint for male_50th (26.4 for female_50th).
    assert "`right_elbow`: 27.9 cm down (26.4 cm down)" in text


def test_person_reference_writes_the_page(tmp_path, capsys):
    out = tmp_path / "person.md"
    assert main(["person-reference", "--out", str(out)]) == 0
    assert out.read_text() == PAGE.read_text() and f"wrote {out}" in capsys.readouterr().out

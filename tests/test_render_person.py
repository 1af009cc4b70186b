"""render-person draws every person variant of a spec, side by side."""

from __future__ import annotations

import numpy as np
from PIL import Image

from assistive_compiler.cli import main
from assistive_compiler.paths import specs_dir


def test_render_person_draws_each_variant(artifact, tmp_path, capsys):
    out = tmp_path / "people.png"
    spec = str(specs_dir() / "tasks" / "feeding.yaml")
    assert main(["render-person", spec, "--robot", "jaco", "--out", str(out), "--out-dir", str(artifact)]) == 0
    assert "male_50th, female_50th" in capsys.readouterr().out
    picture = np.asarray(Image.open(out))
    assert picture.shape == (480, 2 * 360, 3)
    male, female = picture[:, :360], picture[:, 360:]
    assert male.std() > 20 and female.std() > 20  # something is drawn
    assert np.abs(male.astype(int) - female.astype(int)).mean() > 1  # two different bodies

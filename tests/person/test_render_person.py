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
    assert skin_fraction(male) > 0.05 and skin_fraction(female) > 0.05  # seen from the front, whole


def skin_fraction(panel: np.ndarray) -> float:
    """The share of a panel's pixels in the person's skin colour (orange-tan: red high, blue low)."""
    r, g, b = (panel[..., k].astype(int) for k in range(3))
    return float(((r > 150) & (r - b > 60) & (g > 80) & (g < r - 20)).mean())


def test_render_person_sees_a_supine_person_from_above(tmp_path, capsys):
    """Bed Bathing's person lies on the bed: the camera looks from the person's front, which is up,
    not from the bed's foot (where it sat inside the end board and drew only bed colour)."""
    out = tmp_path / "people.png"
    spec = str(specs_dir() / "tasks" / "bed_bathing.yaml")
    assert main(["render-person", spec, "--robot", "jaco", "--out", str(out), "--out-dir", str(tmp_path / "art")]) == 0
    picture = np.asarray(Image.open(out).convert("RGB"))
    for panel in (picture[:, :360], picture[:, 360:]):
        assert skin_fraction(panel) > 0.05  # the whole body is in view (~11% of the panel)

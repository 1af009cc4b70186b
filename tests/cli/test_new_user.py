"""What a new user meets: a damaged cache is recompiled (or named), ``schema --terms`` prints whole
descriptions, ``bench`` reports each finished spec, GIFs play at simulated speed (``--fps``,
MP4), and rendering never changes the simulation (``run`` and ``render`` of a seed agree)."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import artifact_lock
from helpers import cli

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.errors import SpecError
from assistive_compiler.paths import specs_dir
from assistive_compiler.registration import cached_artifact_dir
from assistive_compiler.runtime.env import AssistiveEnv
from assistive_compiler.terms.catalog import terms

TASKS = specs_dir() / "tasks"
FEEDING = TASKS / "feeding.yaml"


@pytest.fixture(scope="module")
def feeding(tmp_path_factory):
    return compile_task(FEEDING, "jaco", tmp_path_factory.mktemp("feeding") / "feeding-jaco").out_dir


def test_a_cut_urdf_in_the_cache_is_recompiled_and_an_env_on_it_names_the_file(feeding, tmp_path):
    out = tmp_path / "copy"
    shutil.copytree(feeding, out)
    robot = out / "urdf" / "robot.urdf"
    whole = robot.read_bytes()
    robot.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(SpecError) as info:
        AssistiveEnv(out)
    assert str(info.value).startswith(f"{out}:1:1: damaged artifact: {robot}: not complete URDF XML (")
    assert "recompile it (assistive-compiler compile SPEC --out" in str(info.value)
    result = compile_task(FEEDING, "jaco", out)
    assert not result.cache_hit and robot.read_bytes() == whole
    assert compile_task(FEEDING, "jaco", out).cache_hit


def test_an_edited_but_well_formed_cache_file_is_caught_by_the_content_hash(feeding, tmp_path):
    out = tmp_path / "copy"
    shutil.copytree(feeding, out)
    robot = out / "urdf" / "robot.urdf"
    robot.write_text(robot.read_text().replace("<robot", "<!-- edited --><robot", 1))
    with pytest.raises(SpecError, match="files differ from what was compiled"):
        AssistiveEnv(out)
    assert not compile_task(FEEDING, "jaco", out).cache_hit


def test_schema_terms_prints_each_description_whole():
    status, out, err = cli("schema", "--terms")
    assert status == 0, err
    flat = " ".join(out.split())
    for category in ("observation", "reward", "preference"):
        for name, tdef in terms(category).items():
            paragraph = " ".join(tdef.doc.strip().split("\n\n")[0].split())
            assert paragraph in flat, name
    assert "Forearm in the opening" in flat  # sleeve_progress: its second docstring line, once cut


@pytest.mark.slow
def test_bench_over_two_specs_prints_a_progress_line_per_spec():
    status, out, err = cli(
        "bench",
        str(FEEDING),
        str(TASKS / "drinking.yaml"),
        "--robot",
        "jaco",
        "--steps",
        "10",
        "--repeats",
        "1",
        "--resets",
        "2",
    )
    assert status == 0, err
    lines = [line for line in err.splitlines() if line.startswith("[")]
    assert [line[:5] for line in lines] == ["[1/2]", "[2/2]"]
    assert "FeedingJaco-v1" in lines[0] and "DrinkingJaco-v1" in lines[1]


def test_gif_plays_at_simulated_speed_and_fps_changes_it(feeding, tmp_path):
    args = ("render", str(FEEDING), "--robot", "jaco", "--out-dir", str(feeding), "--width", "64", "--height", "48")
    status, out, err = cli(*args, "--out", str(tmp_path / "a.gif"))
    assert status == 0, err
    assert "at 2.5 fps" in out
    assert _gif_ms(tmp_path / "a.gif") == (200 // 4 + 1) * 400  # 51 frames, 4 steps of 0.1 s each: a 20 s episode
    status, out, err = cli(*args, "--every", "10", "--fps", "20", "--out", str(tmp_path / "b.gif"))
    assert status == 0, err
    assert _gif_ms(tmp_path / "b.gif") == (200 // 10 + 1) * 50


def _gif_ms(path: Path) -> int:
    """Total play time of a GIF, ms (PIL folds identical frames into one longer frame)."""
    from PIL import Image, ImageSequence

    return sum(frame.info["duration"] for frame in ImageSequence.Iterator(Image.open(path)))


def test_mp4_output(feeding, tmp_path):
    import av

    status, out, err = cli(
        "render",
        str(FEEDING),
        "--robot",
        "jaco",
        "--out-dir",
        str(feeding),
        "--width",
        "65",
        "--height",
        "49",
        "--every",
        "10",
        "--out",
        str(tmp_path / "e.mp4"),
    )
    assert status == 0, err
    with av.open(str(tmp_path / "e.mp4")) as container:
        stream = container.streams.video[0]
        frames = list(container.decode(stream))
        assert (stream.codec_context.width, stream.codec_context.height) == (64, 48)
        assert len(frames) == 200 // 10 + 1 and float(stream.average_rate) == pytest.approx(1.0)


def test_camera_option_is_parsed_and_misuse_is_explained(feeding, tmp_path):
    status, _, err = cli(
        "render", str(FEEDING), "--out-dir", str(feeding), "--out", str(tmp_path / "x.png"), "--camera", "eye=1,2"
    )
    assert status == 2 and "--camera:1:1: 'eye=1,2': expected eye=X,Y,Z, target=X,Y,Z or fov=DEG" in err
    env = AssistiveEnv(
        feeding, render_mode="rgb_array", render_size=(64, 48), camera={"eye": (0.0, -2.0, 1.2), "fov_deg": 30.0}
    )
    env.reset(seed=0)
    default = AssistiveEnv(feeding, render_mode="rgb_array", render_size=(64, 48))
    default.reset(seed=0)
    assert not np.array_equal(env.render(), default.render())
    env.close(), default.close()


def _returns(command: str, spec: Path, robot: str, out: Path, tmp_path: Path) -> float:
    if command == "run":
        status, text, err = cli(
            "run", str(spec), "--robot", robot, "--episodes", "1", "--json", "--quiet", "--out-dir", str(out)
        )
        assert status == 0, err
        return json.loads(text)["episodes"][0]["return"]
    status, text, err = cli(
        "render",
        str(spec),
        "--robot",
        robot,
        "--out-dir",
        str(out),
        "--out",
        str(tmp_path / f"{spec.stem}.png"),
        "--width",
        "32",
        "--height",
        "24",
        "--every",
        "1",
    )
    assert status == 0, err
    return float(re.search(r"return (-?[\d.]+)", text)[1])


@pytest.mark.slow
@pytest.mark.parametrize("spec,robot", [(p.stem, "jaco") for p in sorted(TASKS.glob("*.yaml"))] + [("drinking", "pr2")])
def test_render_never_changes_the_simulation(spec, robot, tmp_path, shared_cache):
    """The same seed gives the same return whether every step is rendered or none is (printed to
    0.1 by render; run's JSON rounded alike). Both play the task compiled in the session's shared
    cache (conftest's ``shared_cache``: compiled once, for this test and the shipped-id tests)."""
    path = TASKS / f"{spec}.yaml"
    out = cached_artifact_dir(path, robot)
    with artifact_lock(path, robot):
        compile_task(path, robot, out)
    ran = _returns("run", path, robot, out, tmp_path)
    rendered = _returns("render", path, robot, out, tmp_path)
    assert f"{ran:.1f}" == f"{rendered:.1f}"

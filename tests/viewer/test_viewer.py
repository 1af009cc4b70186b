"""The browser viewer: ``view`` serves a page on localhost that headless Chromium loads; the 3D scene
renders (software WebGL), the bodies are listed, and SIGINT stops the server cleanly."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from browser import Browser, chromium_path
from conftest import FEEDING

pytest.importorskip("viser", reason='needs the "view" extra')
REPO = Path(__file__).resolve().parents[2]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_view(args: list[str]) -> tuple[subprocess.Popen, str]:
    proc = subprocess.Popen(
        [sys.executable, "-m", "assistive_compiler.cli", "view", *args],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = ""
    while (
        "viewing" not in line
    ):  # "viewing SPEC at URL  (Ctrl-C to stop)" once the page can be loaded (after viser's banner)
        line = proc.stdout.readline()
        if not line:
            break
    if "viewing" not in line:
        proc.kill()
        raise AssertionError(f"view did not start: {line!r} {proc.stderr.read()}")
    return proc, line.split(" at ")[1].split()[0]


def stop_with_sigint(proc: subprocess.Popen) -> tuple[int, str, str]:
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    return proc.returncode, out, err


@pytest.mark.slow
@pytest.mark.skipif(chromium_path() is None, reason="needs Debian's chromium (.ci/run installs it)")
def test_view_page_in_headless_chromium(artifact, tmp_path):
    port = free_port()
    proc, url = start_view(
        [str(FEEDING), "--robot", "jaco", "--policy", "scripted", "--port", str(port), "--out", str(artifact)]
    )
    assert url == f"http://127.0.0.1:{port}"
    browser = Browser()
    try:
        browser.open(url)
        # viser sends the panel's parts one message at a time: wait for each part the test reads
        # (on a loaded machine the Bodies list has arrived seconds before the summary).
        for needle in ("wheelchair", "seed 0 · person", "success yes", "distance_to_mouth"):
            text = browser.wait_for_text(needle, timeout_s=90)
        time.sleep(3)  # let software WebGL draw a few frames
        shot = browser.screenshot(tmp_path / "viewer.png")
    finally:
        browser.close()
        code, out, err = stop_with_sigint(proc)
    for body in ("robot", "person_female_50th", "person_male_50th", "spoon", "bowl", "table", "wheelchair"):
        assert body in text
    assert (
        "seed 0 · person" in text and "success yes" in text and "Reward terms" in text and "distance_to_mouth" in text
    )
    from PIL import Image

    image = np.asarray(Image.open(shot).convert("RGB"), dtype=float)
    assert image.shape[0] > 500 and image.shape[1] > 1000
    assert image.std() > 20  # not blank
    # The 3D view (left of the control panel) shows the scene: many distinct colours, skin and chair among them.
    scene = image[150:, : image.shape[1] - 400]
    assert len(np.unique((scene // 16).reshape(-1, 3), axis=0)) > 40
    assert code in (0, 130) and "Traceback" not in err, err
    assert "viewer stopped" in out


@pytest.mark.slow
def test_view_replay_of_another_artifact_is_refused(artifact, tmp_path):
    from assistive_compiler.policies import make_policy
    from assistive_compiler.record import load_recording, record_episode
    from assistive_compiler.runtime.env import AssistiveEnv

    env = AssistiveEnv(artifact)
    record_episode(env, make_policy("zero", env), 0, tmp_path)
    env.close()
    path = tmp_path / "episode-0000.npz"
    rec = load_recording(path)
    rec.header["content_hash"] = "0" * 64
    rec.save(path)
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "view",
            str(FEEDING),
            "--robot",
            "jaco",
            "--replay",
            str(path),
            "--out-dir",
            str(artifact),
            "--port",
            str(free_port()),
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2
    assert result.stderr.strip().splitlines()[-1] == (
        f"{path}:1:1: recorded from artifact 000000000000 (feeding, jaco), but {FEEDING} for jaco compiles to "
        f"{env.manifest.content_hash[:12]}; view it with the spec and robot it was recorded from"
    )


def test_gui_without_display_is_a_clear_message(artifact, tmp_path):
    env_vars = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    from assistive_compiler.policies import make_policy
    from assistive_compiler.record import record_episode
    from assistive_compiler.runtime.env import AssistiveEnv

    env = AssistiveEnv(artifact)
    record_episode(env, make_policy("zero", env), 0, tmp_path)
    env.close()
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "assistive_compiler.cli",
            "view",
            str(FEEDING),
            "--robot",
            "jaco",
            "--gui",
            "--replay",
            str(tmp_path / "episode-0000.npz"),
            "--out-dir",
            str(artifact),
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        env=env_vars,
        timeout=120,
    )
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert "view --gui: no display ($DISPLAY is not set), so pybullet's GUI cannot open here" in result.stderr

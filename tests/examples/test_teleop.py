"""teleop_keyboard.py: its key and screen logic, then a person at a terminal: a live run paced
to the wall clock, the teleop in a tmux session, keys pressed with send-keys, the screen read
with capture-pane, the vessel's response and the screenshot checked."""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from PIL import Image
from teleop_keyboard import HELP, press, save_png, screen, screenshot

from catabot.bus.messages import CameraFrame, VesselState
from catabot.bus.session import free_port
from tests.paths import REPO


def test_keys_move_each_thruster_in_tenths_within_limits() -> None:
    t: tuple[float, ...] = (0.0, 0.0)
    for key in "rrrU":
        t = press(t, key)
    assert t == (0.3, 0.1)
    assert press(press(t, "f"), "j") == (0.2, 0.0)
    for _ in range(15):
        t = press(press(t, "r"), "J")
    assert t == (1.0, -1.0)
    assert press(t, "x") == t and press((0.5,), "u") == (0.5,)  # one thruster: U/J do nothing


def test_screen_shows_speed_heading_and_thrust() -> None:
    yaw = math.radians(30.0)  # ENU: 30 deg left of east, compass 060
    state = VesselState(
        tick=99, stamp_ns=12_340_000_000, position=(5.0, -2.0, 0.0),
        orientation=(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)),
        linear_velocity=(1.2, 0.5, 0.0), angular_velocity=(0.0, 0.0, 0.0),
        linear_acceleration=(0.0, 0.0, 0.0), angular_acceleration=(0.0, 0.0, 0.0),
    )  # fmt: skip
    text = "\n".join(screen(state, (0.3, -0.1), "saved x.png"))
    assert HELP in text and "12.3 s" in text and "1.30 m/s" in text and "surge +1.20" in text
    assert "60.0 deg" in text and "port +0.3" in text and "starboard -0.1" in text
    assert text.endswith("saved x.png")
    assert "waiting for the vessel's state" in "\n".join(screen(None, (0.0, 0.0), ""))


def frame(color: np.ndarray) -> CameraFrame:
    empty = np.empty((0,), np.uint8)
    return CameraFrame(
        tick=42, stamp_ns=420_000_000, width=4, height=2, hfov_rad=1.0, objects=0, color=color,
        depth=empty, normals=empty, segmentation=empty, instance=empty,
        boxes=np.empty((0, 6), np.float32), box_flags=np.empty((0, 3), np.uint8),
    )  # fmt: skip


def test_save_png_writes_the_colour_image(tmp_path: Path) -> None:
    color = np.arange(24, dtype=np.uint8).reshape(2, 4, 3)
    path = save_png(frame(color), tmp_path / "shots", "ego_camera")
    assert path.name == "ego_camera_00000042.png"
    assert np.array_equal(np.asarray(Image.open(path)), color)
    with pytest.raises(ValueError, match="colour output is switched off"):
        save_png(frame(np.empty((0,), np.uint8)), tmp_path, "x")


def test_a_screenshot_of_a_camera_switched_off_says_so(tmp_path: Path) -> None:
    """The newest frame of a camera switched off is old: the teleop said its colour output
    was off (that old frame's), or saved a view long gone."""
    color = np.zeros((2, 4, 3), np.uint8)
    camera = SimpleNamespace(latest=lambda timeout_s: frame(color))  # stamped 0.42 s
    ego = SimpleNamespace(id="ego", sensor=lambda name: camera)
    said = screenshot(ego, "cam", tmp_path, now_ns=5_000_000_000)  # type: ignore[arg-type]
    assert said.startswith("no screenshot: the camera's newest frame is 4.6 s old")
    assert "catabot set sensor.ego.cam.enabled on" in said and not list(tmp_path.iterdir())
    fresh = screenshot(ego, "cam", tmp_path, now_ns=600_000_000)  # type: ignore[arg-type]
    assert fresh.startswith("saved ego_cam_00000042.png")


TMUX = shutil.which("tmux")


class Terminal:
    """A detached tmux session on its own server socket (nobody else's tmux is touched)."""

    def __init__(self, command: str) -> None:
        self.socket = f"catabot-test-{free_port()}"
        self.tmux("new-session", "-d", "-s", "teleop", "-x", "110", "-y", "24", command)

    def tmux(self, *args: str) -> str:
        assert TMUX is not None
        done = subprocess.run([TMUX, "-L", self.socket, *args], capture_output=True, text=True,
                              timeout=10, check=True)  # fmt: skip
        return done.stdout

    def keys(self, *keys: str) -> None:
        for key in keys:  # one at a time, as fingers do
            self.tmux("send-keys", "-t", "teleop", key)
            time.sleep(0.05)

    def screen(self) -> str:
        return self.tmux("capture-pane", "-p", "-t", "teleop")

    def wait_for(self, text: str, timeout_s: float = 30.0) -> str:
        limit = time.monotonic() + timeout_s
        while text not in (shown := self.screen()):
            assert time.monotonic() < limit, f"{text!r} never shown:\n{shown}"
            time.sleep(0.2)
        return shown

    def close(self) -> None:
        subprocess.run([TMUX or "tmux", "-L", self.socket, "kill-server"], capture_output=True)


@pytest.fixture
def terminal() -> Iterator[type[Terminal]]:
    opened: list[Terminal] = []

    def open_(command: str) -> Terminal:
        opened.append(Terminal(command))
        return opened[-1]

    yield open_  # type: ignore[misc]
    for t in opened:
        t.close()


@pytest.mark.skipif(TMUX is None, reason="tmux is not installed (scripts/system-deps.sh)")
@pytest.mark.timeout(180)
def test_a_person_drives_with_the_keys_and_takes_a_screenshot(
    tmp_path: Path, terminal: type[Terminal]
) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    run = subprocess.Popen(
        [sys.executable, "-m", "catabot", "run", "examples/teleop.json", "--duration", "16",
         "--quiet", "--out", str(tmp_path / "runs"), "--listen", endpoint],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=REPO,
    )  # fmt: skip
    try:
        shots = tmp_path / "shots"
        script = REPO / "examples" / "teleop_keyboard.py"
        teleop = f"{sys.executable} {script} --connect {endpoint} --out {shots}"
        term = terminal(f"cd {REPO} && {teleop}; echo TELEOP-EXIT=$?; sleep 60")
        term.wait_for("speed", timeout_s=60)
        term.keys(*"rrrrr", *"UUUUU")  # both thrusters to half
        term.wait_for("port +0.5   starboard +0.5")
        time.sleep(4.0)  # four seconds of wall clock = of simulated time
        shown = term.screen()
        speed = float(shown.split("speed")[1].split("m/s")[0])
        assert speed > 0.3, shown
        term.keys("f")
        term.wait_for("port +0.4   starboard +0.5")
        term.keys("Space")
        shown = term.wait_for("saved ")
        (png,) = shots.glob("ego_camera_*.png")
        assert f"saved {png.name}" in shown and Image.open(png).size == (320, 240)
        term.keys("C-c")  # as Q does, but the way people often leave: no traceback
        shown = term.wait_for("TELEOP-EXIT=130")
        assert "Traceback" not in shown, shown
        stdout, stderr = run.communicate(timeout=120)
        assert run.returncode == 0, stdout + stderr
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
    (run_dir,) = (tmp_path / "runs").iterdir()
    rows = (run_dir / "vessel.ego.cmd.thrust.csv").read_text().splitlines()[1:]
    sent = [tuple(r.split(",")[2:]) for r in rows]
    assert ("0.5", "0.5") in sent and ("0.4", "0.5") in sent
    assert sent[-1] == ("0.0", "0.0")  # the thrusters stopped before it left
    assert sent.index(("0.5", "0.5")) < sent.index(("0.4", "0.5"))

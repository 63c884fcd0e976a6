"""Drive a vessel from the keyboard in a terminal (curses: works over SSH), with the original
simulator's keys. Commands are free-running thrust (the vessel must have no thrust controller);
run the simulation paced to the wall clock so that a person can steer it:

  R / F   port (left) thruster up / down        U / J   starboard (right) thruster up / down
  Space   save the ego camera's newest frame as a PNG (--out)      Q   quit

catabot run examples/teleop.json --listen tcp/127.0.0.1:7447 &
python examples/teleop_keyboard.py --connect tcp/127.0.0.1:7447
"""

from __future__ import annotations

import contextlib
import curses
import math
import textwrap
from pathlib import Path

from common import clear_errors, parser
from guidance import yaw_of
from PIL import Image

from catabot.client import (
    CameraFrame,
    Client,
    ClientError,
    NoData,
    RunEnded,
    Thrust,
    Vessel,
    VesselState,
)

STEP = 0.1  # thrust per key press, of full (-1..1)
KEYS = {"r": (0, STEP), "f": (0, -STEP), "u": (1, STEP), "j": (1, -STEP)}
HELP = "R/F port up/down   U/J starboard up/down   Space screenshot   Q quit"
STALE_S = 2.0  # a camera frame older than this (sim time) is not the view now


def press(thrust: tuple[float, ...], key: str) -> tuple[float, ...]:
    """The thrust after a key (either case); other keys change nothing. Values stay in -1..1
    and on the 0.1 grid (ten presses from 0 is exactly full)."""
    move = KEYS.get(key.lower())
    if move is None or move[0] >= len(thrust):
        return thrust
    i, step = move
    out = list(thrust)
    out[i] = round(max(-1.0, min(1.0, out[i] + step)), 1)
    return tuple(out)


def screen(state: VesselState | None, thrust: tuple[float, ...], note: str) -> list[str]:
    """The lines shown: speed over ground, heading (compass, from north, clockwise), thrust."""
    lines = ["CataBot teleop", HELP, ""]
    if state is None:
        lines.append("waiting for the vessel's state...")
    else:
        speed = math.hypot(*state.linear_velocity[:2])
        compass = (90.0 - math.degrees(yaw_of(state.orientation))) % 360.0
        x, y, _ = state.position
        lines += [
            f"time     {state.stamp_ns / 1e9:8.1f} s",
            f"speed    {speed:8.2f} m/s   (surge {state.linear_velocity[0]:+.2f} m/s)",
            f"heading  {compass:8.1f} deg  (compass)",
            f"position {x:8.1f} m east, {y:.1f} m north",
        ]
    lines.append("thrust   " + "   ".join(
        f"{name} {v:+.1f}" for name, v in zip(("port", "starboard"), thrust, strict=False)
    ))  # fmt: skip
    return [*lines, "", note]


def save_png(frame: CameraFrame, folder: Path, name: str) -> Path:
    """The frame's colour image as `<name>_<tick>.png` in `folder` (made if missing)."""
    if frame.color.size == 0:
        raise ValueError("the camera's colour output is switched off (outputs.color)")
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}_{frame.tick:08d}.png"
    Image.fromarray(frame.color).save(path)
    return path


def screenshot(ego: Vessel, camera: str, folder: Path, now_ns: int | None = None) -> str:
    """Space: save the newest camera frame; the line to show either way. A frame older than
    STALE_S of sim time at `now_ns` is not the view now: the camera was switched off."""
    try:
        frame = ego.sensor(camera).latest(timeout_s=2.0)
        age = (now_ns - frame.stamp_ns) / 1e9 if now_ns is not None else 0.0
        if age > STALE_S:
            return (f"no screenshot: the camera's newest frame is {age:.1f} s old: is it "
                    f"switched off? (catabot set sensor.{ego.id}.{camera}.enabled on)")  # fmt: skip
        path = save_png(frame, folder, f"{ego.id}_{camera}")
    except (ClientError, ValueError, OSError) as e:
        return f"no screenshot: {e}"
    size, t = f"{frame.width} x {frame.height}", frame.stamp_ns / 1e9
    return f"saved {path.name} ({size}, t={t:.1f} s) in {folder}"


def drive(win: curses.window, ego: Vessel, camera: str, folder: Path, rate_hz: float) -> str:
    """Keys until Q (or RunEnded from the state once the run is over); however it ends
    (Ctrl-C too), the thrusters are stopped: a teleop that leaves must not leave the boat
    running. A closed terminal sends nothing more: the scenario's `command_timeout_s`
    (examples/teleop.json: 1 s) hands the boat back to rest, as a dead-man's switch."""
    try:
        return _keys(win, ego, camera, folder, rate_hz)
    finally:
        with contextlib.suppress(ClientError, OSError):
            ego.send(Thrust([0.0] * ego.info.thrusters))


def _keys(win: curses.window, ego: Vessel, camera: str, folder: Path, rate_hz: float) -> str:
    """A key, the command, the screen, `rate_hz` times a second."""
    curses.curs_set(0)
    win.timeout(round(1000 / rate_hz))
    thrust, note = (0.0,) * ego.info.thrusters, ""
    state: VesselState | None = None
    while True:
        key = win.getch()
        if key in (ord("q"), ord("Q")):
            return "quit"
        if key == ord(" "):
            note = screenshot(ego, camera, folder, state.stamp_ns if state else None)
        elif 0 <= key < 256:
            thrust = press(thrust, chr(key))
        ego.send(Thrust(list(thrust)))
        with contextlib.suppress(NoData):  # the first state may take a moment
            state = ego.state(timeout_s=0.0 if state is not None else 1.0)
        win.erase()
        height, width = win.getmaxyx()
        lines = [part for line in screen(state, thrust, note)
                 for part in textwrap.wrap(line, max(width - 1, 1)) or [""]]  # fmt: skip
        for row, line in enumerate(lines[: height - 1]):  # 80 columns cut "Q quit" off
            win.addnstr(row, 0, line, width - 1)
        win.refresh()


def main() -> None:
    p = parser(__doc__)
    p.add_argument("--camera", default="camera", help="the camera Space saves")
    p.add_argument("--out", type=Path, default=Path("screenshots"), help="folder for the PNGs")
    p.add_argument("--rate", type=float, default=10.0, help="commands (and redraws) per second")
    args = p.parse_args()
    with clear_errors("teleop_keyboard.py"), Client.from_args(args) as sim:
        ego = sim.vessel(args.vessel)
        ego.sensor(args.camera)  # a camera it does not have is told now, not at Space
        try:
            why = curses.wrapper(drive, ego, args.camera, args.out, args.rate)
        except RunEnded as e:
            why = f"the run ended ({e})"
    print(f"teleop: {why}")


if __name__ == "__main__":
    main()

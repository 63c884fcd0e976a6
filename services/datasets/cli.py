"""`catabot dataset export RUN_FOLDER --format yolo|coco|segmentation|kitti -o OUT_DIR`;
`catabot dataset preview RUN_FOLDER -o OUT_DIR`: the labels drawn on the frames (preview.py).

Converts a recorded run after the fact: camera datasets from the run's `dataset/` (labelled
frames), LiDAR scans from its `run.mcap`. `catabot run` calls the same program when the
scenario asks for `recording.export`. Exit codes: 0 written, 2 refused (no such run folder,
no camera or LiDAR, an OUT_DIR that is not empty, a bad option), with one line saying why.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from collections.abc import Callable
from pathlib import Path

from catabot.errors import CataBotError
from catabot.run.answer import OneLineParser, answered
from catabot.run.recorded import RecordedRun
from services.datasets import coco, kitti, preview, segmentation, yolo
from services.datasets.frames import VAL_FRACTION, ExportOptions
from services.datasets.split import MAX_BLOCK_S

FORMATS: dict[str, Callable[[RecordedRun, Path, ExportOptions], str]] = {
    "yolo": yolo.export,
    "coco": coco.export,
    "kitti": kitti.export,
    "segmentation": segmentation.export,
}


def parser() -> OneLineParser:
    p = OneLineParser(prog="catabot dataset", description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="action", required=True)
    exp = sub.add_parser("export", help="convert a recorded run into a training dataset")
    exp.add_argument("run", help="the run folder (runs/<world>-<time>)")
    exp.add_argument("--format", "-f", required=True, choices=list(FORMATS))
    exp.add_argument("--output", "-o", required=True, help="folder to write (new or empty)")
    exp.add_argument(
        "--val-fraction",
        type=float,
        default=None,
        help=f"share of validation (default {VAL_FRACTION:g})",
    )
    exp.add_argument(
        "--split-block-s", type=float, default=None,
        help="simulated seconds that go to train or val together (default: 10, or a tenth "
        "of the run if shorter)",
    )  # fmt: skip
    _box_options(exp)
    look = sub.add_parser("preview", help="each labelled frame with its boxes and mask "
                          "outlines drawn, as PNGs (the boxes the same options keep)")  # fmt: skip
    look.add_argument("run", help="the run folder (runs/<world>-<time>)")
    look.add_argument("--output", "-o", required=True, help="folder to write (new or empty)")
    _box_options(look)
    look.set_defaults(format="preview", val_fraction=VAL_FRACTION, split_block_s=None)
    return p


def _box_options(p: argparse.ArgumentParser) -> None:
    """Which boxes are kept: the export's and the preview's alike, so a preview shows what
    an export with the same options keeps."""
    p.add_argument(
        "--min-box-px", type=int, default=0,
        help="leave out boxes narrower or lower than this many pixels (default 0: keep all)",
    )  # fmt: skip
    p.add_argument(
        "--keep-own", action="store_true",
        help="keep the boxes of each camera's own vessel (its bow in view; left out by default)",
    )  # fmt: skip
    p.add_argument(
        "--min-visible", type=float, default=0.0,
        help="leave out boxes of bodies less visible than this share, 0-1 (default 0: keep all)",
    )  # fmt: skip


class ExportOptionError(CataBotError, ValueError):
    """An option the export cannot use; the message names it."""


def _check(args: argparse.Namespace) -> Path:
    """Options refused in one line, as every tool refuses (argparse's error printed the
    parent command's usage first); a split asked of KITTI, which has none, is refused too."""
    if args.format == "kitti" and (args.val_fraction, args.split_block_s) != (None, None):
        flag = "--val-fraction" if args.val_fraction is not None else "--split-block-s"
        raise ExportOptionError(f"{flag}: a kitti export is not split (every sequence is in "
                                "catabot.yaml's train; move some to valid there)")  # fmt: skip
    args.val_fraction = VAL_FRACTION if args.val_fraction is None else args.val_fraction
    if not 0.0 <= args.val_fraction <= 1.0:
        raise ExportOptionError(f"--val-fraction must be in [0, 1] (got {args.val_fraction})")
    block = args.split_block_s
    if block is not None and not 0 < block <= MAX_BLOCK_S:  # inf: OverflowError, traced
        raise ExportOptionError(f"--split-block-s must be > 0 and at most {MAX_BLOCK_S:g} s "
                                f"(got {block})")  # fmt: skip
    if args.min_box_px < 0:
        raise ExportOptionError(f"--min-box-px must be >= 0 (got {args.min_box_px})")
    if not 0.0 <= args.min_visible <= 1.0:
        raise ExportOptionError(f"--min-visible must be in [0, 1] (got {args.min_visible})")
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise ExportOptionError(f"--output {out} is a file; give a folder (new or empty)")
    if out.exists() and any(out.iterdir()):
        raise ExportOptionError(f"--output {out} exists and is not an empty folder")
    return out


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)

    def export() -> str:
        out = _check(args)
        run = RecordedRun(args.run)
        made = not out.exists()
        out.mkdir(parents=True, exist_ok=True)
        options = ExportOptions(args.val_fraction, args.split_block_s, args.min_box_px,
                                keep_own=args.keep_own, min_visible=args.min_visible)  # fmt: skip
        try:
            summary = _writer(args.format)(run, out, options)
        except BaseException:
            _undo(out, made=made)
            raise
        if args.action == "preview":
            return f"preview in {out}: {summary}"
        ended = run.ended()
        early = "" if ended == "completed" else f" (the run did not complete: {ended})"
        return f"{args.format} dataset in {out}: {summary}{_one_set(args)}{early}"

    return answered(f"dataset {args.action}", export)


def _writer(name: str) -> Callable[[RecordedRun, Path, ExportOptions], str]:
    """A format's writer; `dataset preview` is the format "preview"."""
    return preview.export if name == "preview" else FORMATS[name]


def _one_set(args: argparse.Namespace) -> str:
    """--val-fraction 0 or 1 is allowed (all to one set), but said: data.yaml still names
    the empty set's folder."""
    if args.format == "kitti" or 0.0 < args.val_fraction < 1.0:
        return ""
    empty = "val" if args.val_fraction == 0.0 else "train"
    return f" (--val-fraction {args.val_fraction:g}: the {empty} set is empty)"


def _undo(out: Path, *, made: bool) -> None:
    """A failed export leaves the output as it found it (new, or an empty folder): a half
    export (train annotations, no val) looked whole, and a second try was refused."""
    if made:
        shutil.rmtree(out, ignore_errors=True)
        return
    for part in out.iterdir():
        if part.is_dir() and not part.is_symlink():
            shutil.rmtree(part, ignore_errors=True)
        else:
            part.unlink(missing_ok=True)


if __name__ == "__main__":
    sys.exit(main())

"""What the commands share on the command line: argument types, the rig's, the servo's and the reactive
rolling's options, and the error for flags that do not go together."""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from localizer import (
    CONFIDENCE,
    DEFAULT_JAW,
    OFF_SCALE,
    ROLL_STEP,
    SUCCESS_RADIUS,
    Finger,
    Outline,
    Part,
    RolltouchError,
    StraightJaw,
    load_part,
    parse_jaw,
)

from ..jaw import MAX_ROTATION, PRESS, STEP_RANGE_DEG, PressSettings, ServoSettings
from ..rig import RigError

__all__ = [
    "finite",
    "tcp_port",
    "PLOT_SUFFIXES",
    "roll_degrees",
    "step_degrees",
    "budget_degrees",
    "check_before_moving",
    "writable_file",
    "MAX_STEPS",
    "STEP_DEG",
    "MAX_ROTATION_DEG",
    "UsageError",
    "add_command",
    "part_arguments",
    "read_part",
    "positive",
    "probability",
    "off_scale_argument",
    "off_scale",
    "rig_arguments",
    "servo_arguments",
    "reactive_arguments",
    "pressing",
    "jaw_spec",
    "jaw_argument",
]


#: The command line's defaults in its own units (degrees), from their one home.
STEP_DEG = round(math.degrees(ROLL_STEP), 9)
MAX_ROTATION_DEG = round(math.degrees(MAX_ROTATION), 9)


class UsageError(RolltouchError, ValueError):
    """Flags that do not go together; the command line reports it as argparse's own error."""


def add_command(
    sub: Any, name: str, run: Callable[[argparse.Namespace], int], **kwargs: Any
) -> argparse.ArgumentParser:
    """Add the subcommand ``name`` to ``sub`` (the subparsers of ``rolltouch``) with ``run(args) -> int``
    as what it does; ``kwargs`` go to ``add_parser`` (help, description)."""
    p: argparse.ArgumentParser = sub.add_parser(name, **kwargs)
    p.set_defaults(run=run, parser=p)
    return p


def part_arguments(p: argparse.ArgumentParser, help: str = "part file") -> None:
    """The part: a point file (JSON or CSV) or a CAD drawing (DXF or SVG), and which of the drawing's
    layers or elements holds the outline."""
    p.add_argument("part", help=f"{help}: JSON or CSV points, or a DXF or SVG drawing (its outer outline)")
    p.add_argument("--layer", metavar="NAME", help="DXF: read the outline from this layer")
    p.add_argument("--element", metavar="ID", help="SVG: read the outline from the element with this id")


def read_part(args: argparse.Namespace) -> Part | Outline:
    """The part that :func:`part_arguments` named."""
    return load_part(args.part, layer=getattr(args, "layer", None), element=getattr(args, "element", None))


def _number(text: str, ok: Callable[[float], bool], what: str) -> float:
    """``text`` as a float that ``ok`` accepts (argparse type; else its error naming the value)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    if not ok(value):
        raise argparse.ArgumentTypeError(f"{text!r} must be {what}")
    return value


def probability(text: str) -> float:
    """A probability strictly between 0 and 1 (argparse type)."""
    return _number(text, lambda v: 0 < v < 1, "between 0 and 1")


def odds(text: str) -> float:
    """A probability from 0 up to, not including, 1 (argparse type)."""
    return _number(text, lambda v: 0 <= v < 1, "from 0 up to, not including, 1")


def finite(text: str) -> float:
    """Any finite number (argparse type)."""
    return _number(text, lambda v: True, "finite")


def tcp_port(text: str) -> int:
    """A TCP port for a pair of devices, 1 to 65534 (the DAQ takes the next; argparse type)."""
    value = _number(text, lambda v: v == int(v) and 1 <= v <= 65534, "a whole number from 1 to 65534")
    return int(value)


def positive(text: str) -> float:
    """A positive finite number (argparse type)."""
    return _number(text, lambda v: v > 0, "a positive number")


#: What one command may ask the arm to do, checked before anything moves: a rolling step in
#: :data:`driver.jaw.STEP_RANGE_DEG`; a fixed roll of at most half a turn; a reactive budget of
#: at most two turns; and at most MAX_STEPS rolling steps in all (at the paper's 0.2° and about 0.3 s a
#: step on a real arm, 20 000 steps is under two hours; with every command's reply deadline this
#: bounds a run's time too).
MIN_STEP_DEG, MAX_STEP_DEG = STEP_RANGE_DEG
MAX_ROLL_DEG = 180.0
MAX_BUDGET_DEG = 720.0
MAX_STEPS = 20_000
#: What a --plot may be written as (matplotlib takes the format from the suffix).
PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def roll_degrees(text: str) -> float:
    """One fixed roll's rotation, degrees: finite, nonzero, at most :data:`MAX_ROLL_DEG` (argparse type)."""
    return _number(
        text, lambda v: v != 0 and abs(v) <= MAX_ROLL_DEG, f"nonzero and at most {MAX_ROLL_DEG:g}° either way"
    )


def step_degrees(text: str) -> float:
    """A rolling step, degrees, in [:data:`MIN_STEP_DEG`, :data:`MAX_STEP_DEG`] (argparse type)."""
    return _number(
        text, lambda v: MIN_STEP_DEG <= v <= MAX_STEP_DEG, f"between {MIN_STEP_DEG:g}° and {MAX_STEP_DEG:g}°"
    )


def budget_degrees(text: str) -> float:
    """A reactive rotation budget, degrees, in (0, :data:`MAX_BUDGET_DEG`] (argparse type)."""
    return _number(text, lambda v: 0 < v <= MAX_BUDGET_DEG, f"positive and at most {MAX_BUDGET_DEG:g}°")


def check_before_moving(args: argparse.Namespace, outputs: dict[str, tuple[str, ...]]) -> None:
    """Refuse, before the first command reaches the arm, what would fail later: rolls that turn both
    ways, more than :data:`MAX_STEPS` rolling steps, and output files that cannot be written (``outputs``:
    argument name → the suffixes it must end in, empty for any). Raises :class:`UsageError`."""
    rolls = getattr(args, "roll", None) or []
    if len({r > 0 for r in rolls}) > 1:
        raise UsageError(f"--roll {' --roll '.join(f'{r:g}' for r in rolls)}: all rolls must turn the same way")
    step = getattr(args, "step", None)
    if step is not None:
        total = args.max_rotation if getattr(args, "reactive", False) else sum(abs(r) for r in rolls) or 35.0
        steps = total / step
        if steps > MAX_STEPS:
            raise UsageError(
                f"{total:g}° in steps of {step:g}° is {steps:.0f} rolling steps, more than {MAX_STEPS}: "
                "use a larger --step or less rotation"
            )
    for name, suffixes in outputs.items():
        value = getattr(args, name, None)
        if value is not None:
            writable_file(value, f"--{name.replace('_', '-')}", suffixes)


def writable_file(path: str, flag: str, suffixes: tuple[str, ...] = ()) -> None:
    """Refuse an output path that is a folder, lies in no writable folder, or lacks its suffix."""
    p = Path(path)
    if suffixes and p.suffix.lower() not in suffixes:
        raise UsageError(f"{flag} {path}: the file name must end in {' or '.join(suffixes)}")
    if p.is_dir():
        raise UsageError(f"{flag} {path} is a folder: give a file name")
    folder = p.parent if str(p.parent) else Path(".")
    if not folder.is_dir():
        raise UsageError(f"{flag} {path}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise UsageError(f"{flag} {path}: not writable")


def rig_arguments(p: argparse.ArgumentParser) -> None:
    """--arm, --daq and --timeout of the commands that talk to a rig."""
    p.add_argument("--arm", required=True, metavar="URL", help="arm controller: device path or pyserial URL")
    p.add_argument("--daq", required=True, metavar="URL", help="DAQ: device path or pyserial URL")
    p.add_argument("--timeout", type=positive, default=2.0, metavar="S", help="reply deadline (default 2 s)")


def servo_arguments(p: argparse.ArgumentParser) -> None:
    """--servo-gain and --no-guard: hold the force with the arm's servo after every press."""
    p.add_argument(
        "--servo-gain",
        type=positive,
        metavar="G",
        help="after every press, hold Δv1 with the arm's 1 kHz force servo at this gain (N/N) "
        "for 0.3 s, refusing a loop that loses the part or rings above 0.05 V (docs/passivity.md); default: no servo",
    )
    p.add_argument("--no-guard", action="store_true", help="run that servo without its passivity observer/controller")


def reactive_arguments(p: argparse.ArgumentParser) -> None:
    """--reactive and its options: roll until the belief is sure (driver.jaw.reactive)."""
    p.add_argument(
        "--reactive",
        action="store_true",
        help=f"instead of fixed rolls, roll step by step until the contact is known within {SUCCESS_RADIUS} mm "
        "with --confidence, or --max-rotation is rolled (docs/robustness.md)",
    )
    p.add_argument(
        "--confidence",
        type=probability,
        default=CONFIDENCE,
        metavar="P",
        help=f"reactive: probability within {SUCCESS_RADIUS} mm that stops the rolling (default {CONFIDENCE})",
    )
    p.add_argument(
        "--max-rotation",
        type=budget_degrees,
        default=MAX_ROTATION_DEG,
        metavar="DEG",
        help=f"reactive: rotation budget, both directions counted (default {MAX_ROTATION_DEG:g}°)",
    )
    p.add_argument(
        "--policy",
        choices=("seek", "spread"),
        help="reactive, straight jaw: which way to roll while two places hold the belief: seek (turn towards the "
        "way expected to tell them apart soonest, a face or a corner included; the default) or spread (the "
        "baseline: by how much the unexplored curvature each way separates the two leading places)",
    )
    off_scale_argument(p)


def off_scale_argument(p: argparse.ArgumentParser, replay: bool = False) -> None:
    """--off-scale: the wheel's prior probability that the part is off its model's size (its filter's
    ``off_scale``). A replay's default is the one its record was made with."""
    default = "the record's, else " if replay else ""
    p.add_argument(
        "--off-scale",
        type=odds,
        metavar="P",
        help="wheel: the prior probability that the part is off its model's size (made to another revision, "
        f"scaled on export), its scale then within about 1%%; sure only where the readings tell the size "
        f"(default {default}{OFF_SCALE}; 0: the part is its model's size, sure sooner on faces and near-circular "
        "stretches)",
    )


def off_scale(args: argparse.Namespace, finger: Finger, recorded: object = None) -> float:
    """The wheel's ``off_scale`` from --off-scale, else ``recorded`` (a replayed record's), else the default;
    refused for a straight jaw, which carries no scale."""
    given = getattr(args, "off_scale", None)
    if isinstance(finger, StraightJaw):
        if given is not None:
            raise UsageError(f"--off-scale {given:g} is the wheel's: the finger is {finger}, which carries no scale")
        return 0.0
    if given is not None:
        return float(given)
    if recorded is None:
        return OFF_SCALE
    if isinstance(recorded, bool) or not isinstance(recorded, (int, float)) or not 0 <= recorded < 1:
        raise RigError(f"the record's off_scale {recorded!r} is not a probability in [0, 1): give --off-scale")
    return float(recorded)


def pressing(args: argparse.Namespace) -> PressSettings:
    """The presses that --servo-gain and --no-guard ask for: the paper's, then the arm's servo if given."""
    if args.servo_gain is None:
        if args.no_guard:
            raise UsageError("--no-guard needs --servo-gain: without the servo there is nothing to guard")
        return PRESS
    return PressSettings(servo=ServoSettings(gain=args.servo_gain, guard=not args.no_guard))


def jaw_spec(text: str) -> Finger:
    """argparse type of ``--jaw``: a finger (:func:`localizer.parse_jaw`). The rig models the paper's 100 mm
    straight jaw (its wrist and the calibration's ±50 mm taps) and wheels of any radius."""
    try:
        finger = parse_jaw(text)
    except RolltouchError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    if isinstance(finger, StraightJaw) and finger != DEFAULT_JAW:
        raise argparse.ArgumentTypeError(
            f"{text}: the rig models the paper's {DEFAULT_JAW} jaw only (its wrist and the calibration's ±50 mm "
            f"taps); use {DEFAULT_JAW} or a wheel, e.g. wheel:5"
        )
    return finger


def jaw_argument(p: argparse.ArgumentParser, default: Finger | None = DEFAULT_JAW) -> None:
    """--jaw: the finger, the paper's straight jaw or a wheel on an axle encoder (docs/wheel.md)."""
    p.add_argument(
        "--jaw",
        type=jaw_spec,
        default=default,
        metavar="straight:100|wheel:MM",
        help="the finger: the paper's 100 mm straight jaw"
        + (" (default)" if default is not None else "")
        + ", or a wheel of radius MM on an axle encoder (docs/wheel.md)",
    )

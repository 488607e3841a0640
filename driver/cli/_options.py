"""What the commands share on the command line: argument types, the rig's, the servo's and the reactive
rolling's options, and the error for flags that do not go together."""

from __future__ import annotations

import argparse
import math

from localizer import ROLL_STEP, SUCCESS_RADIUS, Outline, Part, RolltouchError, load_part

from ..procedures import PRESS, PressSettings, ServoSettings
from ..reactive import CONFIDENCE, MAX_ROTATION

__all__ = [
    "STEP_DEG",
    "MAX_ROTATION_DEG",
    "UsageError",
    "add_command",
    "part_arguments",
    "read_part",
    "positive",
    "probability",
    "rig_arguments",
    "servo_arguments",
    "reactive_arguments",
    "pressing",
]


#: The command line's defaults in its own units (degrees), from their one home.
STEP_DEG = round(math.degrees(ROLL_STEP), 9)
MAX_ROTATION_DEG = round(math.degrees(MAX_ROTATION), 9)


class UsageError(RolltouchError, ValueError):
    """Flags that do not go together; the command line reports it as argparse's own error."""


def add_command(sub, name: str, run, **kwargs) -> argparse.ArgumentParser:
    """Add the subcommand ``name`` to ``sub`` (the subparsers of ``rolltouch``) with ``run(args) -> int``
    as what it does; ``kwargs`` go to ``add_parser`` (help, description)."""
    p = sub.add_parser(name, **kwargs)
    p.set_defaults(run=run, parser=p)
    return p


def part_arguments(p, help: str = "part file") -> None:
    """The part: a point file (JSON or CSV) or a CAD drawing (DXF or SVG), and which of the drawing's
    layers or elements holds the outline."""
    p.add_argument("part", help=f"{help}: JSON or CSV points, or a DXF or SVG drawing (its outer outline)")
    p.add_argument("--layer", metavar="NAME", help="DXF: read the outline from this layer")
    p.add_argument("--element", metavar="ID", help="SVG: read the outline from the element with this id")


def read_part(args) -> Part | Outline:
    """The part that :func:`part_arguments` named."""
    return load_part(args.part, layer=getattr(args, "layer", None), element=getattr(args, "element", None))


def _number(text: str, ok, what: str) -> float:
    """``text`` as a float that ``ok`` accepts (argparse type; else its error naming the value)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(value) and ok(value)):
        raise argparse.ArgumentTypeError(f"{text!r} must be {what}")
    return value


def probability(text: str) -> float:
    """A probability strictly between 0 and 1 (argparse type)."""
    return _number(text, lambda v: 0 < v < 1, "between 0 and 1")


def positive(text: str) -> float:
    """A positive finite number (argparse type)."""
    return _number(text, lambda v: v > 0, "a positive number")


def rig_arguments(p) -> None:
    """--arm, --daq and --timeout of the commands that talk to a rig."""
    p.add_argument("--arm", required=True, metavar="URL", help="arm controller: device path or pyserial URL")
    p.add_argument("--daq", required=True, metavar="URL", help="DAQ: device path or pyserial URL")
    p.add_argument("--timeout", type=positive, default=2.0, metavar="S", help="reply deadline (default 2 s)")


def servo_arguments(p) -> None:
    """--servo-gain and --no-guard: hold the force with the arm's servo after every press."""
    p.add_argument(
        "--servo-gain",
        type=positive,
        metavar="G",
        help="after every press, hold Δv1 with the arm's 1 kHz force servo at this gain (N/N) "
        "for 0.3 s, refusing a loop that loses the part or rings above 0.05 V (docs/passivity.md); default: no servo",
    )
    p.add_argument("--no-guard", action="store_true", help="run that servo without its passivity observer/controller")


def reactive_arguments(p) -> None:
    """--reactive and its options: roll until the belief is sure (driver.reactive)."""
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
        type=positive,
        default=MAX_ROTATION_DEG,
        metavar="DEG",
        help=f"reactive: rotation budget, both directions counted (default {MAX_ROTATION_DEG:g}°)",
    )


def pressing(args) -> PressSettings:
    """The presses that --servo-gain and --no-guard ask for: the paper's, then the arm's servo if given."""
    if args.servo_gain is None:
        if args.no_guard:
            raise UsageError("--no-guard needs --servo-gain: without the servo there is nothing to guard")
        return PRESS
    return PressSettings(servo=ServoSettings(gain=args.servo_gain, guard=not args.no_guard))

"""The ``rolltouch`` command line, built from a registry of command groups.

Each group is a module with ``register(sub)``, which adds its subcommands to ``sub`` (the
subparsers of ``rolltouch``) with :func:`add_command`: a parser of its own and the function that
runs it. driver's groups are :data:`COMMAND_GROUPS`; another package adds its own as an entry
point of the group :data:`ENTRY_POINT_GROUP` (``bench`` adds ``montecarlo`` so), so that driver
never imports the packages above it.

Angles are given in degrees on the command line and converted to radians at this edge; lengths
are in mm. Any error of ours ends the command with one line on stderr and exit status 2; flags
that do not go together are argparse's own error (usage, status 2).
"""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
from collections.abc import Callable, Sequence
from importlib import metadata
from typing import Any

from localizer import RolltouchError

from ..blas import one_blas_thread
from ..link import handling
from ._options import UsageError, add_command

__all__ = [
    "main",
    "build_parser",
    "add_command",
    "UsageError",
    "Terminated",
    "COMMAND_GROUPS",
    "ENTRY_POINT_GROUP",
]

#: driver's command groups, in the order ``rolltouch --help`` lists them.
COMMAND_GROUPS = (
    "driver.cli.offline",
    "driver.cli.simulated",
    "driver.cli.rig",
    "driver.cli.export",
    "driver.cli.show",
)
#: The entry-point group through which other packages add command groups (a ``register(sub)`` each).
ENTRY_POINT_GROUP = "rolltouch.commands"
#: What an interrupted command says it did unless the arm's safe stop says (the exception's notes) or
#: the command sets its own (``interrupted`` in its parser's defaults, or on ``args`` as it goes).
INTERRUPTED = "no arm command was being run"


def _version() -> str:
    try:
        return metadata.version("rolltouch")
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


def _registrars() -> list[Callable[[Any], None]]:
    """The ``register`` functions: driver's groups, then the entry points' (by name)."""
    found = [importlib.import_module(name).register for name in COMMAND_GROUPS]
    for ep in sorted(metadata.entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
        try:
            found.append(ep.load())
        except Exception as exc:  # a broken add-on must not take the rig's commands with it
            print(f"rolltouch: warning: command group {ep.name!r} ({ep.value}) not loaded: {exc}", file=sys.stderr)
    return found


def build_parser() -> argparse.ArgumentParser:
    """The ``rolltouch`` parser with every registered command group."""
    parser = argparse.ArgumentParser(prog="rolltouch", description="Localize a jaw on a known curved part by rolling.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for register in _registrars():
        register(sub)
    return parser


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP (``timeout``, systemd, a closed terminal): handled as Ctrl-C is, so that the
    arm is stopped and the jaw backed off on the way out."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def _terminate(signum: int, frame: object) -> None:
    raise Terminated(signum)


def _notes(exc: BaseException) -> str:
    """What the host did on the way out (e.g. the safe stop), as the exception's notes say."""
    return "; ".join(getattr(exc, "__notes__", []))


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``rolltouch`` with ``argv`` (default: the process's); returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with handling(("SIGTERM", "SIGHUP"), _terminate), one_blas_thread():  # SIGTERM handled as Ctrl-C is
            return int(args.run(args))
    except UsageError as exc:
        args.parser.error(str(exc))  # exits with status 2
    except RolltouchError as exc:
        notes = _notes(exc)
        print(f"rolltouch: error: {exc}" + (f" ({notes})" if notes else ""), file=sys.stderr)
        return 2
    except (OSError, MemoryError) as exc:  # not ours (RigError is an OSError too, handled above)
        shown = f"{exc.filename}: {exc.strerror}" if isinstance(exc, OSError) and exc.filename else str(exc)
        print(f"rolltouch: error: {shown or type(exc).__name__}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        what = f"terminated by {exc.args[0]}" if isinstance(exc, Terminated) else "interrupted"
        done = _notes(exc) or getattr(args, "interrupted", INTERRUPTED)
        print(f"\nrolltouch: {what}: {done}", file=sys.stderr)
        return 128 + exc.signum if isinstance(exc, Terminated) else 130
    except BrokenPipeError:
        return 0
    return 2

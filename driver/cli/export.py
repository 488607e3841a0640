"""``rolltouch export``: a run's record (a run log or a trace) as an MCAP file, for Foxglove and ROS 2 tools."""

from __future__ import annotations

import argparse
from typing import Any

from ._options import add_command, writable_file

__all__ = ["register", "export_command"]


def register(sub: Any) -> None:
    """Add ``export`` to the subparsers ``sub``."""
    p = add_command(
        sub,
        "export",
        export_command,
        help="write a run log or a trace as an MCAP file (Foxglove, ROS 2 bags)",
        description=(
            "Write a run's record as MCAP: JSON messages on /rolltouch/wrist, /rolltouch/arm, /rolltouch/belief "
            "and, for simulations, /rolltouch/truth (driver.records.mcap_export)."
        ),
    )
    p.add_argument("record", metavar="TRACE_OR_LOG", help="a trace (.npz, either finger) or a run log (.jsonl)")
    p.add_argument("--mcap", required=True, metavar="OUT.mcap", help="the MCAP file to write")


def export_command(args: argparse.Namespace) -> int:
    from ..records import export_mcap

    writable_file(args.mcap, "--mcap", (".mcap",))
    counts = export_mcap(args.record, args.mcap)
    shown = ", ".join(f"{topic} {n}" for topic, n in sorted(counts.items()))
    print(f"{sum(counts.values())} messages written to {args.mcap}: {shown}")
    return 0

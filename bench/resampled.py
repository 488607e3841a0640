"""World parts that are their model resampled: the same curve through other points.

A part made from a drawing, or scanned and fitted again, is the model's curve sampled again: a spline
through the model's points at its knots and half-way between them differs from the model by less than
a micron on smooth stretches and by microns to tens of microns near tight bends, and nowhere else
("the model resampled" in docs/robustness.md). For
each part file of a family this writes such a world part of the same name, for a study's
``[world] world_parts``::

    python -m bench.resampled bench/parts/heldout-f --out bench/parts/heldout-f-resampled
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import numpy.typing as npt

from localizer import Part, load_part

__all__ = ["resampled", "write_resampled"]


def resampled(part: Part, per_knot: int = 2) -> npt.NDArray[np.float64]:
    """The points (mm) of ``part`` at ``per_knot`` equal steps of arc between each two of its knots (its
    knots among them), first point first."""
    knots = np.asarray(part.arc_at_param(np.arange(part.n_knots, dtype=float)), dtype=float)
    gaps = np.diff(np.append(knots, part.perimeter))
    arcs = (knots[:, None] + gaps[:, None] * np.arange(per_knot)[None, :] / per_knot).ravel()
    out: npt.NDArray[np.float64] = np.asarray(part.point_at_arc(part.wrap_arc(arcs)), dtype=float)
    return out


def write_resampled(folder: Path, out: Path) -> list[Path]:
    """A resampled world part for every JSON part file of ``folder``, written to ``out`` under the same names."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in sorted(folder.glob("*.json")):
        part = load_part(path)
        if not isinstance(part, Part):
            continue
        target = out / path.name
        doc = {"name": f"{part.name} (resampled)", "units": "mm", "points": np.round(resampled(part), 6).tolist()}
        target.write_text(json.dumps(doc) + "\n")
        written.append(target)
    return written


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.resampled", description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", type=Path, help="a folder of JSON part files")
    ap.add_argument("--out", type=Path, required=True, help="where to write the world parts")
    args = ap.parse_args(argv)
    for p in write_resampled(args.folder, args.out):
        print(p)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Draw the shipped CAD outlines as they are read: pieces by kind, corners by sign, the first point
and the direction of travel. ``python -m bench.reports.cad_figure --out docs/generated/cad``."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from localizer import CircularArc, CubicBezier, Line, load_outline

if TYPE_CHECKING:
    from collections.abc import Sequence

ROOT = Path(__file__).resolve().parents[2]
PARTS = (ROOT / "parts" / "bracket.dxf", ROOT / "parts" / "profile.svg")
COLOURS = {Line: "tab:blue", CircularArc: "tab:orange", CubicBezier: "tab:green"}


def draw(paths: Sequence[Path], out: Path) -> Path:
    """One panel per outline; returns the PNG written into ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(paths), figsize=(5.5 * len(paths), 4.2))
    for ax, path in zip(np.atleast_1d(axes), paths):
        o = load_outline(path)
        for piece in o.pieces:
            xy = piece.point(np.linspace(0.0, piece.length, 200))
            ax.plot(xy[:, 0], xy[:, 1], color=COLOURS[type(piece)], lw=2)
        for c in o.corners:
            x, y = o.point_at_arc(c.arc)
            ax.plot(x, y, "^" if c.angle > 0 else "v", color="k" if c.angle > 0 else "tab:red", ms=8)
        x0, y0 = o.point_at_arc(0.0)
        t = float(o.tangent_angle_at_arc(0.0))
        ax.annotate(
            "", xy=(x0 + 6 * np.cos(t), y0 + 6 * np.sin(t)), xytext=(x0, y0), arrowprops={"arrowstyle": "->", "lw": 1.5}
        )
        ax.plot(x0, y0, "o", color="k", ms=5)
        ax.set_title(f"{path.name}: perimeter {o.perimeter:.3f} mm, {len(o.corners)} corners", fontsize=9)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
    handles = [plt.Line2D([], [], color=c, lw=2, label=k.__name__) for k, c in COLOURS.items()]  # type: ignore[attr-defined,unused-ignore]
    handles += [
        plt.Line2D([], [], ls="", marker="^", color="k", label="convex corner"),  # type: ignore[attr-defined,unused-ignore]
        plt.Line2D([], [], ls="", marker="v", color="tab:red", label="concave corner"),  # type: ignore[attr-defined,unused-ignore]
        plt.Line2D([], [], ls="", marker="o", color="k", label="first point (arrow: travel)"),  # type: ignore[attr-defined,unused-ignore]
    ]
    fig.legend(handles=handles, loc="lower center", ncol=6, fontsize=8)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    out.mkdir(parents=True, exist_ok=True)
    png = out / "outlines.png"
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.reports.cad_figure", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "generated" / "cad")
    args = ap.parse_args(argv)
    print(f"written {draw(PARTS, args.out)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

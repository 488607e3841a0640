"""The figures of docs/wheel.md: a wheel finger rolling into a concave stretch, the boundary it reaches
against the straight jaw's, and the Cramér–Rao bound of one roll as a function of its radius.

``python -m bench.reports.wheel_figure --out docs/generated/wheel`` (a few seconds). Both fingers'
reach with the library's default clearance (0.1 mm): `localizer.Reach` (touchable at some place on
the jaw) and `localizer.WheelReach`.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from localizer import Reach, WheelJaw, load_part, roll_bound, wheel_reach_for

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    import numpy.typing as npt

    from localizer import Outline, Part

    FloatArray: TypeAlias = npt.NDArray[np.float64]

ROOT = Path(__file__).resolve().parents[2]
PARTS = {
    "kidney (shipped)": ROOT / "parts" / "kidney.csv",
    "trefoil (shipped)": ROOT / "parts" / "trefoil.json",
    "glyph (tuning family)": ROOT / "bench" / "parts" / "tuning" / "glyph-06.json",
    "filleted polygon (tuning family)": ROOT / "bench" / "parts" / "tuning" / "filleted-11.json",
}
RADII = (1.0, 2.0, 3.0, 5.0, 8.0, 12.0, 20.0)
SPACING = 0.05  # mm between the sample's points

#: Assumed rig figures for the bound (docs/wheel.md, "What a roll measures"): the arm's encoder step
#: (the `paper` preset's), a 12-bit axle encoder, the calibrated radius's relative error, and the
#: wrist's direction error after the orientation servo.
ARM_SD = math.radians(0.03) / math.sqrt(12.0)
AXLE_SD = 2 * math.pi / 4096 / math.sqrt(12.0)
RADIUS_REL = 2e-4
DIRECTION_SD = math.radians(0.02)
ROLL = 15.0  # mm, the roll whose bound is drawn


def sample(part: Part | Outline) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(arc, points, tangent angle, curvature) every SPACING mm."""
    s = np.arange(0.0, part.perimeter, SPACING)
    return (
        s,
        np.asarray(part.point_at_arc(s)),
        np.asarray(part.tangent_angle_at_arc(s)),
        np.asarray(part.curvature_at_arc(s)),
    )


def roll_sds(kappa_ends: Iterable[FloatArray], radius: float, texture: float) -> tuple[float, FloatArray]:
    """The standard deviations (mm, rad) of one roll's L and Ω for a wheel of ``radius`` mm, one
    reading at each end (docs/wheel.md): the axle encoder and the calibrated radius's error in L;
    the arm encoder, the wrist's residual direction and the surface texture the disc follows (tilts
    of variance a / (2 R*) at each end, R* = 1 / (1/r + κ) the contact's relative radius) in Ω."""
    var_l = 2 * (radius * AXLE_SD) ** 2 + (ROLL * RADIUS_REL) ** 2
    texture_var = sum(0.5 * texture * np.maximum(1.0 / radius + k, 0.0) for k in kappa_ends)
    var_o = 2 * ARM_SD**2 + 2 * DIRECTION_SD**2 + texture_var
    return math.sqrt(var_l), np.sqrt(var_o)


def figures(out: Path) -> dict[str, Any]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    numbers: dict[str, Any] = {"radii_mm": list(RADII), "reach": {}, "bound_mm": {}}

    # 1. a wheel of 5 mm rolling along the kidney's concave side
    # each part read once, so that each wheel's reach is built once (wheel_reach_for keeps it)
    parts = {name: load_part(path) for name, path in PARTS.items()}
    kidney = parts["kidney (shipped)"]
    s, pts, th, ka = sample(kidney)
    ax = axes[0]
    ax.plot(pts[:, 0], pts[:, 1], "k", lw=1.5)
    r = 5.0
    ok = wheel_reach_for(kidney, WheelJaw(r), SPACING).touchable(s)
    concave = np.flatnonzero(ok & (ka < -1e-3))
    centre = pts + r * np.c_[np.sin(th), -np.cos(th)]
    ax.plot(*centre[ok].T, ".", color="tab:blue", ms=0.6, label=f"axle path, wheel r = {r:g} mm")
    for k in concave[:: max(1, concave.size // 5)]:
        ax.add_patch(plt.Circle(tuple(centre[k]), r, fill=False, color="tab:blue", lw=1))  # type: ignore[attr-defined,unused-ignore]
        ax.plot(*pts[k], "o", color="k", ms=3)
    ax.plot(*pts[~ok].T, ".", color="tab:red", ms=1.0, label="not reached by it")
    ax.set_aspect("equal")
    ax.set_title("a 5 mm wheel on the kidney's concave side", fontsize=10)
    ax.legend(fontsize=8, loc="lower left")

    # 2. the reachable fraction of the boundary against the radius, with the straight jaw's
    ax = axes[1]
    for name, part in parts.items():
        s, pts, th, ka = sample(part)
        frac = [float(wheel_reach_for(part, WheelJaw(rr), SPACING).touchable(s).mean()) for rr in RADII]
        jaw = float(np.mean(Reach(part).touchable(s)))
        numbers["reach"][name] = {"wheel": dict(zip(map(str, RADII), frac)), "straight:100": jaw}
        line = ax.plot(RADII, frac, "o-", label=name)[0]
        ax.axhline(jaw, color=line.get_color(), ls=":", lw=1)
    ax.set_xscale("log")
    ax.set_xlabel("wheel radius r (mm)")
    ax.set_ylabel("fraction of the boundary reached")
    ax.set_title("reach (dotted: the 100 mm straight jaw)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)

    # 3. the bound of one 15 mm roll from the kidney's concave starts the wheel reaches, median
    ax = axes[2]
    s, pts, th, ka = sample(kidney)
    step = int(round(ROLL / SPACING))
    for texture, style in ((0.0, "o-"), (0.5e-3, "s--")):
        med = []
        for rr in RADII:
            ok = wheel_reach_for(kidney, WheelJaw(rr), SPACING).touchable(s)
            starts = [i for i in np.flatnonzero(ok & (ka < 0)) if ok[(i + step) % ka.size] and ok[i : i + step].all()]
            idx = np.asarray(starts, dtype=int)
            if idx.size == 0:
                med.append(float("nan"))
                continue
            sd_l, sd_o = roll_sds((ka[idx], ka[(idx + step) % ka.size]), rr, texture)
            b = roll_bound(kidney, s[idx], ROLL, sd_length=sd_l, sd_turn=sd_o)
            med.append(float(np.median(b)))
        numbers["bound_mm"][f"texture {texture * 1e3:g} um"] = dict(zip(map(str, RADII), med))
        ax.plot(RADII, med, style, label=f"surface texture amplitude {texture * 1e3:g} µm")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wheel radius r (mm)")
    ax.set_ylabel("bound on the start (mm), median over starts")
    ax.set_title(f"one {ROLL:g} mm roll from the kidney's concave starts", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "wheel.png", dpi=110)
    plt.close(fig)
    (out / "wheel.json").write_text(json.dumps(numbers, indent=1))
    return numbers


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.reports.wheel_figure", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=Path("docs/generated/wheel"))
    args = ap.parse_args(argv)
    numbers = figures(args.out)
    print(json.dumps(numbers, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

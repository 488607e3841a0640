"""Generated CAD drawings, fixed by a seed: outlines from DXF and SVG files no setting was chosen on.

The shipped drawings (``parts/bracket.dxf``, ``parts/profile.svg``) were in the tests while the
filter and the rig were made to work on outlines, so a study on them is not a held-out result. These
families are drawn as a user's CAD system would write them, one file per part:

- ``plate`` (DXF): a random polygon of 5 to 8 corners (one pushed in half the time: a concave
  corner), each corner filleted (radius 3 to 12 mm) with probability 0.6 and sharp otherwise, as one
  closed ``LWPOLYLINE`` with bulges; a hole and a title on other layers;
- ``cam`` (SVG): a closed path of 4 to 6 cubic Béziers through points of a perturbed circle, joined
  smoothly except at one or two sharp corners, in a ``viewBox`` with a physical size in mm;
- ``dee`` (DXF): an elliptical arc (an ``ELLIPSE`` of semi-axes 30-60 and 15-40 mm, sweep 180° to
  270°) closed by straight faces;
- ``nurbs`` (DXF): a rational cubic ``SPLINE`` (weights 0.5 to 2) through a perturbed circle's
  control points, open and clamped, closed by one straight face.

A draw that does not read as a simple closed outline is redrawn from the same generator.
``python -m bench.cad_families --seed S --count N --out DIR`` writes the files; the family is a
function of (seed, count) alone. ``bench/parts/cad-heldout`` is seed 20261202, count 12: made after
the filter, the rig and the two-roll rules on outlines were written and run once for reporting.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import cast

import numpy as np
import numpy.typing as npt

__all__ = ["CAD_KINDS", "CAD_HELDOUT_SEED", "draw", "write_cad_family"]

CAD_KINDS = ("plate", "cam", "dee", "nurbs")
CAD_HELDOUT_SEED = 20261202


def _polygon(rng: np.random.Generator) -> npt.NDArray[np.float64]:
    corners = int(rng.integers(5, 9))
    ang = np.sort(rng.uniform(0, 2 * np.pi, corners))
    while np.min(np.diff(np.r_[ang, ang[0] + 2 * np.pi])) < 0.5:
        ang = np.sort(rng.uniform(0, 2 * np.pi, corners))
    rad = rng.uniform(45.0, 90.0, corners)
    if rng.random() < 0.5:
        rad[int(rng.integers(corners))] *= 0.5
    return cast(npt.NDArray[np.float64], np.c_[rad * np.cos(ang), rad * np.sin(ang)])


def _plate(rng: np.random.Generator, path: Path) -> str:
    """A polygon with some corners filleted, as an LWPOLYLINE with bulges (module notes)."""
    import ezdxf

    v = _polygon(rng)
    n = len(v)
    verts: list[tuple[float, float, float]] = []
    filleted = 0
    for i in range(n):
        p, q, r = v[i - 1], v[i], v[(i + 1) % n]
        a_in, a_out = (q - p) / np.linalg.norm(q - p), (r - q) / np.linalg.norm(r - q)
        turn = math.atan2(a_in[0] * a_out[1] - a_in[1] * a_out[0], float(a_in @ a_out))
        if rng.random() < 0.6:
            shorter = float(min(np.linalg.norm(q - p), np.linalg.norm(r - q)))
            f = min(rng.uniform(3.0, 12.0), 0.3 * shorter / max(abs(math.tan(turn / 2)), 1e-6))
            back = f * abs(math.tan(turn / 2))
            t0, t1 = q - a_in * back, q + a_out * back
            verts.append((float(t0[0]), float(t0[1]), math.tan(turn / 4)))  # the fillet's bulge
            verts.append((float(t1[0]), float(t1[1]), 0.0))
            filleted += 1
        else:
            verts.append((float(q[0]), float(q[1]), 0.0))
    doc = ezdxf.new()  # type: ignore[attr-defined,unused-ignore]
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline(verts, format="xyb", close=True, dxfattribs={"layer": "OUTLINE"})
    centre = v.mean(axis=0)
    msp.add_circle((float(centre[0]), float(centre[1])), 4.0, dxfattribs={"layer": "HOLES"})
    msp.add_text("PLATE", dxfattribs={"layer": "TITLE", "height": 3.0})
    doc.saveas(path)
    return f"plate, {n} corners, {filleted} filleted"


def _cam(rng: np.random.Generator, path: Path) -> str:
    """Cubic Béziers through a perturbed circle, smooth but at one or two corners (module notes)."""
    k = int(rng.integers(4, 7))
    ang = np.sort(rng.uniform(0, 2 * np.pi, k))
    while np.min(np.diff(np.r_[ang, ang[0] + 2 * np.pi])) < 0.6:
        ang = np.sort(rng.uniform(0, 2 * np.pi, k))
    rad = rng.uniform(35.0, 60.0, k)
    pts = np.c_[rad * np.cos(ang), rad * np.sin(ang)]
    sharp = set(rng.choice(k, size=int(rng.integers(1, 3)), replace=False).tolist())
    # tangents: Catmull-Rom, except at a sharp point, where each side points at its neighbour
    tangents_out, tangents_in = [], []
    for i in range(k):
        prev, nxt = pts[i - 1], pts[(i + 1) % k]
        t = 0.5 * (nxt - prev)
        if i in sharp:
            tangents_in.append((pts[i] - prev) * 0.4)
            tangents_out.append((nxt - pts[i]) * 0.4)
        else:
            tangents_in.append(t / 3 * 1.0)
            tangents_out.append(t / 3 * 1.0)

    # y down in SVG: write -y so that the part read back (y flipped) is this one
    def svg(p: npt.NDArray[np.float64]) -> str:
        return f"{p[0] + 100:.6f} {-p[1] + 100:.6f}"

    d = [f"M {svg(pts[0])}"]
    for i in range(k):
        j = (i + 1) % k
        c1, c2 = pts[i] + tangents_out[i], pts[j] - tangents_in[j]
        d.append(f"C {svg(c1)} {svg(c2)} {svg(pts[j])}")
    d.append("Z")
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="0 0 200 200">\n'
        f'  <path id="cam" fill="none" stroke="black" d="{" ".join(d)}"/>\n'
        '  <circle id="bore" cx="100" cy="100" r="5" fill="none" stroke="black"/>\n</svg>\n'
    )
    return f"cam, {k} cubic Béziers, {len(sharp)} sharp corner(s)"


def _dee(rng: np.random.Generator, path: Path) -> str:
    """An elliptical arc closed by straight faces (module notes)."""
    import ezdxf

    a, b = rng.uniform(30.0, 60.0), rng.uniform(15.0, 40.0)
    a, b = max(a, b), min(a, b)  # the major axis first
    sweep = rng.uniform(math.pi, 1.5 * math.pi)
    t0 = -0.5 * sweep
    tilt = rng.uniform(0, math.pi)
    u = np.array([math.cos(tilt), math.sin(tilt)]) * a
    w = np.array([-math.sin(tilt), math.cos(tilt)]) * b
    end = u * math.cos(t0 + sweep) + w * math.sin(t0 + sweep)
    start = u * math.cos(t0) + w * math.sin(t0)
    doc = ezdxf.new()  # type: ignore[attr-defined,unused-ignore]
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_ellipse((0, 0), major_axis=(float(u[0]), float(u[1])), ratio=b / a, start_param=t0, end_param=t0 + sweep)
    # the closing faces: from the arc's end to a point inside, then back to its start (a corner there)
    inner = 0.25 * (start + end)
    msp.add_line((float(end[0]), float(end[1])), (float(inner[0]), float(inner[1])))
    msp.add_line((float(inner[0]), float(inner[1])), (float(start[0]), float(start[1])))
    doc.saveas(path)
    return f"dee, ellipse {a:.1f} x {b:.1f} mm over {math.degrees(sweep):.0f} deg, two faces"


def _nurbs(rng: np.random.Generator, path: Path) -> str:
    """A rational cubic SPLINE closed by one face (module notes)."""
    import ezdxf

    k = int(rng.integers(6, 10))
    ang = np.linspace(0.15 * np.pi, 1.85 * np.pi, k) + rng.uniform(-0.08, 0.08, k)
    rad = rng.uniform(40.0, 65.0, k)
    cps = [(float(r * math.cos(t)), float(r * math.sin(t))) for r, t in zip(rad, ang, strict=True)]
    weights = rng.uniform(0.5, 2.0, k)
    weights[0] = weights[-1] = 1.0
    doc = ezdxf.new()  # type: ignore[attr-defined,unused-ignore]
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_rational_spline(cps, weights.tolist(), degree=3)
    msp.add_line(cps[-1], cps[0])
    doc.saveas(path)
    return f"nurbs, {k} control points, weights {weights.min():.2f}-{weights.max():.2f}, one face"


_MAKERS = {"plate": (_plate, ".dxf"), "cam": (_cam, ".svg"), "dee": (_dee, ".dxf"), "nurbs": (_nurbs, ".dxf")}


def draw(kind: str, rng: np.random.Generator, out: Path, name: str) -> tuple[Path, str]:
    """One drawing of ``kind`` written to ``out/name.<suffix>``, redrawn until it reads as a simple
    closed outline; returns the path and a description."""
    from localizer import PartError, load_outline

    make, suffix = _MAKERS[kind]
    path = out / f"{name}{suffix}"
    for _ in range(50):
        desc = make(rng, path)
        try:
            load_outline(path)
        except PartError:
            continue
        return path, desc
    raise RuntimeError(f"no valid {kind} drawing in 50 draws")


def write_cad_family(seed: int, count: int, out: str | Path) -> list[tuple[Path, str]]:
    """``count`` drawings, the kinds in turn, from ``numpy.random.SeedSequence(seed)``, into ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rngs = [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(count)]
    return [
        draw(CAD_KINDS[i % len(CAD_KINDS)], rng, out, f"{CAD_KINDS[i % len(CAD_KINDS)]}-{i:02d}")
        for i, rng in enumerate(rngs)
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.cad_families", description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--count", type=int, default=12)
    ap.add_argument("--out", required=True, metavar="DIR")
    args = ap.parse_args(argv)
    for path, desc in write_cad_family(args.seed, args.count, args.out):
        print(f"{path}: {desc}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Regenerate the example parts in this folder: ``python parts/make_parts.py``.

Every part is a list of points in mm, counter-clockwise, written as the JSON
part file of DESIGN.md (and one as plain CSV).
"""

import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def polar(n, radius):
    a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    r = radius(a)
    return np.round(np.c_[r * np.cos(a), r * np.sin(a)], 6)


PARTS = {
    # convex cam, 40 knots
    "cam": ("convex cam, 40 knots", polar(40, lambda a: 40 + 5 * np.cos(a) + 2 * np.sin(2 * a))),
    # symmetric: an ellipse 80 x 50 mm, 48 knots (roots come in symmetric pairs)
    "ellipse": ("ellipse 80 x 50 mm, 48 knots", polar(48, lambda a: 1.0 / np.sqrt((np.cos(a) / 40) ** 2 + (np.sin(a) / 25) ** 2))),
    # non-convex, 90 knots, six inflections: the benchmark part
    "trefoil": ("non-convex trefoil, 90 knots, 6 inflections", polar(90, lambda a: 50 + 8 * np.cos(3 * a) + 3 * np.sin(5 * a))),
}


def main():
    for name, (desc, pts) in PARTS.items():
        doc = {"name": name, "description": desc, "units": "mm", "points": pts.tolist()}
        (HERE / f"{name}.json").write_text(json.dumps(doc) + "\n")
    # a kidney-shaped non-convex part as plain CSV (x,y in mm)
    pts = polar(60, lambda a: 35 + 9 * np.cos(2 * a) + 4 * np.cos(a))
    with open(HERE / "kidney.csv", "w") as f:
        f.write("# kidney-shaped part, 60 knots, x,y in mm\nx,y\n")
        for x, y in pts:
            f.write(f"{x},{y}\n")


if __name__ == "__main__":
    main()

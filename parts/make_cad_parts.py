"""Regenerate the CAD example parts in this folder: ``python parts/make_cad_parts.py``.

``bracket.dxf``: a machined bracket, 80 x 40 mm, as one closed LWPOLYLINE on layer OUTLINE: straight
faces, three fillets (R8, R8, R10), a sharp corner at its first point (0, 0), a 20 x 10 mm notch in
its top face (two convex and two concave corners); a Ø8 hole on layer HOLES and a title on layer
TITLE, which the outline ignores. Perimeter 208 + 13π mm.

``profile.svg``: a cam profile in mm (width/height in mm over a viewBox of the same size): two
cubic Béziers joined tangentially, a straight flank and a closing face, with corners where the
lines meet. y points down in SVG; the outline is read with y up.
"""

import math
from pathlib import Path

import ezdxf

HERE = Path(__file__).resolve().parent
QUARTER = math.tan(math.radians(90.0) / 4.0)  # the DXF bulge of a counter-clockwise quarter circle

BRACKET = [  # (x, y, bulge of the piece that starts here), counter-clockwise from the sharp corner
    (0.0, 0.0, 0.0),
    (72.0, 0.0, QUARTER),
    (80.0, 8.0, 0.0),
    (80.0, 32.0, QUARTER),
    (72.0, 40.0, 0.0),
    (50.0, 40.0, 0.0),
    (50.0, 30.0, 0.0),
    (30.0, 30.0, 0.0),
    (30.0, 40.0, 0.0),
    (10.0, 40.0, QUARTER),
    (0.0, 30.0, 0.0),
]
#: The bracket's perimeter in closed form, mm: its faces plus the fillets' quarter circles.
BRACKET_PERIMETER = 72 + 24 + 22 + 10 + 20 + 10 + 20 + 30 + math.pi / 2 * (8 + 8 + 10)

PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="80mm" viewBox="-10 -30 100 80">
  <title>cam profile, mm</title>
  <path id="profile" fill="none" stroke="black" stroke-width="0.2"
        d="M 0 0 C 20 -15 50 -15 70 0 C 85 11.25 85 38 70 50 L 0 50 Z"/>
  <circle id="bore" cx="35" cy="25" r="6" fill="none" stroke="black" stroke-width="0.2"/>
  <text x="0" y="45" font-size="4">PROFILE A</text>
</svg>
"""


def main() -> None:
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4  # mm
    msp = doc.modelspace()
    msp.add_lwpolyline(BRACKET, format="xyb", close=True, dxfattribs={"layer": "OUTLINE"})
    msp.add_circle((65.0, 20.0), 4.0, dxfattribs={"layer": "HOLES"})
    msp.add_text("BRACKET B-1", dxfattribs={"layer": "TITLE", "height": 3.0, "insert": (20.0, 15.0)})
    doc.saveas(HERE / "bracket.dxf")
    (HERE / "profile.svg").write_text(PROFILE)
    print(f"bracket.dxf: perimeter {BRACKET_PERIMETER:.9f} mm; profile.svg")


if __name__ == "__main__":
    main()

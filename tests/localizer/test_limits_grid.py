"""Every table built per part is sized before it is built (localizer.geometry._limits.check_grid): a part too
large for one (a drawing in metres read as mm, a wheel of a nanometre) is refused by name with the
figure, at once, and the largest parts the project ships or generates are not.

The refusals are asked of parts beyond each limit; nothing of their tables may be allocated (the
point), so each test takes well under a second. The parts that must pass are checked by stopping each
builder right after its check (:func:`passed_checks`), without building the tables."""

import importlib
import math
import tracemalloc
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import localizer.geometry._limits as limits
from localizer import (
    MAX_ARRAY_BYTES,
    MAX_GRID_POINTS,
    MAX_PAIRWISE_POINTS,
    ContactFilter,
    CubicBezier,
    Line,
    PartError,
    ParticleFilter,
    Reach,
    Segment,
    WheelFilter,
    WheelJaw,
    WheelReach,
    load_part,
    march_grid,
    outline_from_pieces,
    outline_segments,
    part_from_points,
)
from localizer.chain._outline_chain import chain_likelihood, chain_paper
from localizer.contact._tracks import ModeTracks
from localizer.filters._belief import find_modes
from localizer.solve._table import arc_table

ROOT = Path(__file__).resolve().parents[2]
STAR = ROOT / "bench/parts/heldout-g/star-12.json"  # 1030 mm: the filter must still run on it

#: Every module that calls check_grid before building a table.
CHECKING = (
    "localizer.filters._contact_state",
    "localizer.contact._tracks",
    "localizer.contact._reach",
    "localizer.contact._wheel",
    "localizer.filters._wheel_state",
    "localizer.chain._outline_chain",
    "localizer.solve._outline_solver",
    "localizer.solve._table",
    "localizer.solve._march_grid",
    "localizer.filters._belief",
)


def rectangle(w, h, name="rect"):
    return outline_from_pieces(
        [Line((0.0, 0.0), (w, 0.0)), Line((w, 0.0), (w, h)), Line((w, h), (0.0, h)), Line((0.0, h), (0.0, 0.0))],
        name=name,
    )


def ellipse(a, b, n=64, name="ellipse"):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return part_from_points(np.c_[a * np.cos(t), b * np.sin(t)], name=name)


def scaled_star(factor):
    star = load_part(STAR)
    return part_from_points(star.points * factor, name=f"star-12 x{factor:g}")


def blob(radius, name="blob"):
    """A closed chain of eight cubic Béziers round a wobbly ellipse of about ``radius`` mm."""
    n, k = 8, 4 / 3 * math.tan(math.pi / 16)
    pts = []
    for i in range(n):
        a = 2 * math.pi * i / n
        r = radius * (1 + 0.15 * math.cos(3 * a))
        pts.append((r * math.cos(a), 0.7 * r * math.sin(a), a, r))
    pieces = []
    for i in range(n):
        x0, y0, a0, r0 = pts[i]
        x1, y1, a1, r1 = pts[(i + 1) % n]
        c1 = (x0 - k * r0 * math.sin(a0), y0 + 0.7 * k * r0 * math.cos(a0))
        c2 = (x1 + k * r1 * math.sin(a1), y1 - 0.7 * k * r1 * math.cos(a1))
        pieces.append(CubicBezier((x0, y0), c1, c2, (x1, y1)))
    return outline_from_pieces(pieces, name=name)


class Passed(Exception):
    """A builder got past its check (raised in place of building the table)."""


@pytest.fixture
def passed_checks(monkeypatch):
    """Each module's check_grid as itself, then :class:`Passed` instead of building: the checks a builder
    asks, on the real limits, and the figures it asked them with."""
    asked = []

    def check_then_stop(*args, **kwargs):
        limits.check_grid(*args, **kwargs)
        asked.append((args, kwargs))
        raise Passed

    for name in CHECKING:
        monkeypatch.setattr(importlib.import_module(name), "check_grid", check_then_stop)
    return asked


def refused(build, match):
    """``build()`` raises PartError matching ``match`` having allocated under 64 MB (nothing was built:
    what it refuses would take gigabytes; counted, not timed, so a loaded machine does not matter)."""
    tracemalloc.start()
    try:
        with pytest.raises(PartError, match=match):
            build()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64 * 2**20


# ------------------------------------------------------------------------------------- the refusals


def test_the_filter_refuses_a_part_in_metres_by_its_grid_of_starts():
    # the rectangle: 1e6 x 5e5 mm, 15 kB of DXF
    big = rectangle(1e6, 5e5, name="rect")
    refused(
        lambda: ContactFilter(big),
        r"part 'rect' is 3 000 000 mm around: the filter's grid every 0\.02 mm would need 1\.5e8 points, "
        r"more than the 262 144 it may have; is the part in the right units \(mm\)\?",
    )


def test_the_filter_refuses_a_part_whose_sums_would_not_fit_its_array():
    # 2061 mm: 103 000 starts is within the grid's limit, but (2·413 + 85) sums each are 0.7 GB
    star = scaled_star(2)
    assert star.perimeter / 0.02 < MAX_GRID_POINTS
    refused(
        lambda: ContactFilter(star),
        r"part 'star-12 x2' is 2 061 mm around: the filter's grid every 0\.02 mm would need 103 \d{3} points, "
        r"7\d\d\.\d MB, more than the 512 MB it may have",
    )


def test_the_rolling_tracks_refuse_a_grid_too_fine():
    big = ellipse(5e3, 3e3, name="oval")
    refused(lambda: ParticleFilter(big), r"part 'oval' is 25 \d{3} mm around: the rolling tracks' grid")
    refused(lambda: ModeTracks(big, 0.02), r"rolling tracks' grid every 0\.02 mm would need 1 2\d\d \d{3} points")


def test_the_reach_table_refuses_a_part_whose_points_it_cannot_compare_pairwise():
    # 5 km of perimeter would be fine for a linear table; each of the reach's points looks at every other
    big = ellipse(1000, 600)
    assert big.perimeter / 0.2 < MAX_GRID_POINTS
    refused(
        lambda: Reach(big),
        r"part 'ellipse' is 5 1\d\d mm around: the straight jaw's reach table's grid every 0\.2 mm would need "
        r"25 \d{3} points \(each against all\), more than the 16 384 it may have",
    )


def test_a_wheel_too_small_for_its_reach_table_is_refused_on_any_part():
    small = ellipse(40, 25)
    refused(
        lambda: WheelReach(small, WheelJaw(1e-9)),
        r"part 'ellipse' is 207 mm around: the wheel:1e-09 reach table's grid every 8e-09 mm would need "
        r"2\.6e10 points, more than the 262 144 it may have; is the radius in mm\?",
    )
    # a wheel of an eighth of the table's step or more needs no finer table
    with pytest.raises(PartError, match=r"wheel:5 reach table's grid every 0\.05 mm would need 2\.1e7 points"):
        WheelReach(scaled_star(1000), WheelJaw(5.0))


def test_the_wheel_filter_refuses_a_part_in_metres():
    big = ellipse(3e3, 1e3, name="oval")
    refused(lambda: WheelFilter(big, WheelJaw(5.0)), r"part 'oval' is 13 \d{3} mm around: the wheel filter's grid")


def test_the_roll_chain_refuses_a_drawing_in_metres():
    big = rectangle(1e6, 5e5, name="rect")
    chain = ((12.0, math.radians(20.0)),)
    refused(
        lambda: chain_likelihood(big, chain, 1.0, 0.5, math.radians(0.03), 0.5),
        r"part 'rect' is 3 000 000 mm around: the roll chain's grid every 0\.01 mm would need 3e8 states",
    )


def test_the_roll_chain_refuses_a_turn_error_that_would_split_the_corners_too_finely():
    small = rectangle(60.0, 40.0, name="plate")
    refused(
        lambda: chain_likelihood(small, ((12.0, 0.3),), 1.0, 0.5, 1e-7, 0.5),
        r"part 'plate' is 200 mm around: the roll chain's grid every 0\.01 mm would need 6 303 \d{3} states, .*"
        r"6 283 \d{3} of them at its 4 corners, one every 1e-06 rad of their jumps: give a larger sd_turn",
    )


def test_the_paper_rule_refuses_a_face_it_would_sample_too_finely():
    big = rectangle(1e6, 5e5, name="rect")
    face = Segment(0.0, 12.0, 0.0, 12.0, 12.0, 0.0, kind="continuum", span=9e5)
    refused(
        lambda: chain_paper(big, ((12.0, 0.0),), [face], 1.0, 0.004),
        r"part 'rect' is 3 000 000 mm around: the paper rule's grid every 0\.01 mm would need 9e7 starts along a face",
    )


def test_the_outline_solver_refuses_a_drawing_in_metres():
    big = rectangle(1e6, 5e5, name="rect")
    refused(
        lambda: outline_segments(big, 12.0, math.radians(20.0)),
        r"part 'rect' is 3 000 000 mm around: the outline solver's grid every 0\.01 mm would need 3e8 cells",
    )


def test_the_outline_solvers_bezier_table_refuses_more_curve_than_it_may_tabulate():
    # 1.7 m of Béziers: the solver's cells (0.01 mm) are within the limit, the Bézier table's (0.005 mm) not
    curvy = blob(300.0)
    assert curvy.perimeter / 0.01 < MAX_GRID_POINTS < curvy.perimeter / 0.005
    refused(
        lambda: outline_segments(curvy, 12.0, math.radians(20.0)),
        r"part 'blob' is 1 \d{3} mm around: the outline solver's Bézier table's grid every 0\.005 mm would need "
        r"3\d\d \d{3} cells",
    )


def test_the_arc_table_refuses_a_part_of_too_many_knots():
    # the cells grow with the knots: a stand-in part of a million knots (none of them built)
    many = SimpleNamespace(name="scan", perimeter=1000.0, n_knots=1_000_000, cells_per_piece=1, _tables={})
    refused(
        lambda: arc_table(many),
        r"part 'scan' is 1 000 mm around: the arc table's grid every 0\.001 mm would need 1 000 000 cells, more "
        r"than the 262 144 it may have; it has 1000000 knots",
    )


def test_the_march_refuses_a_grid_too_large_for_its_memory():
    # 300 knots at the paper's step of 1e-5: 3e7 cells of three numbers
    part = ellipse(40, 25, n=300)
    refused(
        lambda: march_grid(part, 1e-5),
        r"part 'ellipse' is 207 mm around: the march's grid every 1e-05 of a knot would need 3e7 cells, 686\.6 MB, "
        r"more than the 512 MB it may have; it has 300 knots; take a coarser step",
    )


def test_the_belief_refuses_bins_too_fine():
    part = ellipse(40, 25)
    w = np.full(10, 0.1)
    arcs = np.linspace(0.0, 100.0, 10)
    refused(
        lambda: find_modes(part, w, arcs, arcs, 1e-9),
        r"part 'ellipse' is 207 mm around: the belief's grid every 1e-09 mm would need 2\.1e11 bins",
    )


def test_the_limits_hold_what_their_notes_say():
    assert MAX_GRID_POINTS == 2**18 and MAX_PAIRWISE_POINTS == 2**14 and MAX_ARRAY_BYTES == 2**29


# ------------------------------------------------------------------- the parts that must still pass

SHIPPED = sorted(p for p in (ROOT / "parts").iterdir() if p.suffix in (".json", ".csv", ".dxf", ".svg"))
#: The largest generated parts: the longest (glyph-18, 1151 mm; the stars of 1030 mm), the longest drawing
#: (plate-04, 457 mm), the most knots (filleted-19 resampled, 176) and the largest arc table (glyph-06 resampled).
GENERATED = [
    ROOT / "bench/parts/heldout-e/glyph-18.json",
    STAR,
    ROOT / "bench/parts/heldout-g-resampled/star-12.json",
    ROOT / "bench/parts/cad-heldout/plate-04.dxf",
    ROOT / "bench/parts/heldout-f-resampled/filleted-19.json",
    ROOT / "bench/parts/tuning-resampled/glyph-06.json",
]


@pytest.mark.parametrize("path", SHIPPED + GENERATED, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_the_largest_parts_pass_every_check(path, passed_checks):
    part = load_part(path)
    spline = not part.corners and hasattr(part, "n_knots")
    builders = [
        lambda: ContactFilter(part),
        lambda: ParticleFilter(part),
        lambda: ModeTracks(part, 0.02),
        lambda: Reach(part),
        lambda: WheelReach(part, WheelJaw(2.5)),
        lambda: find_modes(part, np.ones(1), np.zeros(1), np.zeros(1), 0.3),
    ]
    if spline:
        builders += [lambda: WheelFilter(part, WheelJaw(5.0)), lambda: march_grid(part, 1e-5), lambda: arc_table(part)]
    else:
        chain = ((12.0, math.radians(20.0)), (8.0, math.radians(-10.0)))
        builders += [
            lambda: chain_likelihood(part, chain, 1.0, 0.5, math.radians(0.03), 0.5),
            lambda: outline_segments(part, 12.0, math.radians(20.0)),
        ]
    for build in builders:
        with pytest.raises(Passed):
            build()
    assert len(passed_checks) == len(builders)


def test_the_largest_arc_table_refines_within_the_limit():
    # the arc table is checked at each refinement: the generated part of the most cells needs 34 816
    part = load_part(ROOT / "bench/parts/tuning-resampled/glyph-06.json")
    assert arc_table(part).h.size == 34_816


def test_the_filter_sizes_its_array_as_it_builds_it(monkeypatch):
    # the check's figures are the filter's own: its starts and 8 bytes per basis column (default settings)
    asked = []
    monkeypatch.setattr(
        "localizer.filters._contact_state.check_grid",
        lambda *a, **k: asked.append((a, k)) or limits.check_grid(*a, **k),
    )
    for part in (ellipse(40, 25), rectangle(60.0, 40.0)):
        f = ContactFilter(part)
        (args, kwargs), *_ = asked[-1:]
        assert args[3] == f.grid.size and kwargs["point_bytes"] == 8 * f._up.shape[0]


def test_the_1_m_star_runs_the_filter_within_the_array_limit(passed_checks):
    # 51 527 starts of 499 sums: 196 MiB, the measured size of its filter's array
    with pytest.raises(Passed):
        ContactFilter(load_part(STAR))
    (args, kwargs) = passed_checks[0]
    assert args[3] == 51_527 and kwargs["point_bytes"] == 8 * 499
    assert args[3] * kwargs["point_bytes"] < 0.4 * MAX_ARRAY_BYTES


# ------------------------------------------------------------------------------------ the drawing's pieces
def lwpolyline_dxf(xy, path, splice):
    """A drawing of one closed LWPOLYLINE through the points ``xy`` (a list of (x, y)), written by ezdxf;
    with ``splice``, ezdxf writes it with the first vertex and the others are spliced into its text after
    it as ezdxf writes vertices (x and y by ``str``, no width or bulge when zero): the same file without
    ezdxf's export of each vertex (2 s at MAX_PIECES)."""
    import ezdxf

    doc = ezdxf.new()
    written = xy[:1] if splice else xy
    doc.modelspace().add_lwpolyline([], close=True).lwpoints.extend([(x, y, 0, 0, 0) for x, y in written])
    doc.saveas(path)
    if splice:

        def tags(points):
            return "".join(f" 10\n{x}\n 20\n{y}\n" for x, y in points)

        one = path.read_text(encoding="utf-8")
        head = " 90\n1\n 70\n1\n" + tags(xy[:1])  # the vertex count, the closed flag, the vertex
        assert one.count(head) == 1
        path.write_text(one.replace(head, f" 90\n{len(xy)}\n 70\n1\n" + tags(xy)), encoding="utf-8")
    return path


def test_a_drawing_of_more_pieces_than_an_outline_may_have_is_refused_before_they_are_built(tmp_path, monkeypatch):
    """One LWPOLYLINE of MAX_PIECES + 1 vertices (10 MB) is refused by its count, before its pieces
    are made (the 60 MB one of 1 300 000 vertices took 45 s and 2.6 GB before); loose LINEs and SVG
    segments are counted as they are read, an SVG's numbers before it is parsed (here against a limit
    of 50)."""
    import ezdxf

    from localizer import MAX_PIECES, load_outline

    t = np.linspace(0.0, 2 * np.pi, MAX_PIECES + 1, endpoint=False)
    xy = np.c_[600 * np.cos(t), 200 * np.sin(t)].tolist()
    # the spliced file is ezdxf's own, byte for byte, on a few of the points (with ezdxf's option for
    # comparing files: the same date and ids in every file)
    with monkeypatch.context() as m:
        m.setattr(ezdxf.options, "write_fixed_meta_data_for_testing", True)
        few = xy[:: MAX_PIECES // 6]
        spliced = lwpolyline_dxf(few, tmp_path / "spliced.dxf", splice=True).read_bytes()
        assert spliced == lwpolyline_dxf(few, tmp_path / "ezdxf.dxf", splice=False).read_bytes()
    lwpolyline_dxf(xy, tmp_path / "dense.dxf", splice=True)
    with pytest.raises(PartError, match=r"dense.dxf: more than 262 144 pieces .* coarser chord tolerance"):
        load_outline(tmp_path / "dense.dxf")

    import localizer.geometry._cad_loops as cad_loops

    monkeypatch.setattr(cad_loops, "MAX_PIECES", 50)
    square = [(0, 0), (10, 0), (10, 10), (0, 10)]
    doc = ezdxf.new()
    for i in range(60):
        a, b = square[i % 4], square[(i + 1) % 4]
        doc.modelspace().add_line((a[0] + 20 * (i // 4), a[1]), (b[0] + 20 * (i // 4), b[1]))
    doc.saveas(tmp_path / "lines.dxf")
    with pytest.raises(PartError, match=r"lines.dxf: more than 50 pieces"):
        load_outline(tmp_path / "lines.dxf")
    path = " ".join(f"M {20 * i} 0 h 10 v 10 h -10 Z" for i in range(15))
    (tmp_path / "many.svg").write_text(f'<svg xmlns="http://www.w3.org/2000/svg"><path d="{path}"/></svg>')
    with pytest.raises(PartError, match=r"many.svg: more than 50 pieces"):
        load_outline(tmp_path / "many.svg")
    # and one whose numbers alone say so, before the parser builds its segments
    dense = " ".join(f"{math.cos(a):.4f},{math.sin(a):.4f}" for a in np.linspace(0, 6.28, 200, endpoint=False))
    (tmp_path / "dense.svg").write_text(f'<svg xmlns="http://www.w3.org/2000/svg"><polygon points="{dense}"/></svg>')
    with pytest.raises(PartError, match=r"dense.svg: more than 50 pieces"):
        load_outline(tmp_path / "dense.svg")
    (tmp_path / "few.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0 h 10 v 10 h -10 Z"/></svg>'
    )
    assert load_outline(tmp_path / "few.svg").perimeter == pytest.approx(40.0)

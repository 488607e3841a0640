"""The exact feasible-segment solver (paper §II, DESIGN "The localization problem").

Find every arc position σ where a segment of arc length L starting there has
total curvature Ω:

    g(σ) = θ(σ + L) - θ(σ) - Ω = 0,     g'(σ) = κ(σ + L) - κ(σ),

with θ the unwrapped tangent angle as a function of arc position (exact, no
integration) and κ the signed curvature.

Completeness comes from a certificate on every cell of a grid in σ (the certificates of
:func:`localizer.solve._certify.certify_cells`, which the outline solver uses; here compiled,
:func:`localizer.solve._solver_kernels.cell_pass`). The part's table bounds |dκ/dσ| on each of its cells;
a cell of the grid spans a run of whole table cells at its start, and the largest bound over those and
over the table cells its end sweeps bounds |g''| on it. With g and g' known exactly at the cell's
ends a cell is certified to hold one root, none, a near-double root (at a width of ``double_width``
mm) or a flat stretch (|g| below ``flat_tol`` everywhere: a circular arc of radius L/Ω, one
``"continuum"`` segment with its extent), or it is bisected; no root is ever skipped.

Bracketed roots start from the cubic Hermite root on their bracket and are settled by Newton on the
exact spline to ``tol`` mm (compiled, :func:`localizer.solve._solver_kernels.polish`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from .._errors import QueryError
from ..geometry import Outline, Part
from ._certify import merge_flats
from ._march import PAPER_MARCH, MarchOptions, march
from ._outline_solver import outline_segments
from ._segment import DIRECTIONS, KINDS, Segment
from ._solver_kernels import TOO_MANY_CELLS, cell_pass, hermite_roots, polish
from ._table import ArcTable, arc_table

__all__ = ["feasible_segments", "ExactOptions", "EXACT", "METHODS"]

# The cell pass starts from about this many cells of whole table cells (fewer on a table of fewer cells):
# on the trefoil (360 table cells) and three traced outlines (2880) a query cost least between 32
# and 128; one cell per table cell cost 2 to 5 times more.
_SUPER_CELLS = 64

#: Solver methods accepted by :func:`feasible_segments`.
METHODS = ("exact", "march")


# ---------------------------------------------------------------- evaluators
def _g_table(table: ArcTable, sigma: np.ndarray, length: float, turn: float) -> tuple[np.ndarray, np.ndarray]:
    """Tabulated g and g' at arc positions ``sigma``."""
    th_s, k_s = table.theta_kappa(sigma)
    th_e, k_e = table.theta_kappa(sigma + length)
    return th_e - th_s - turn, k_e - k_s


def _g_exact(
    part: Part, sigma: np.ndarray, length: float, turn: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Exact g, g' and the parameters of both ends at arc positions ``sigma``."""
    ts = part.param_at_arc(sigma)
    te = part.param_at_arc(sigma + length)
    _, th_s, k_s, _ = part.state(ts)
    _, th_e, k_e, _ = part.state(te)
    return th_e - th_s - turn, k_e - k_s, ts, te


def _polish(
    part: Part, table: ArcTable, sigma: np.ndarray, length: float, turn: float, tol: float, max_iter: int = 6
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Newton on the exact system ℓ(s, e) = L, Φ(s, e) = Ω in the spline parameters.

    Starts from the tabulated parameters of a root of the tabulated g; each
    step is exact up to rounding, so two steps take a 1e-9 mm start to
    machine precision. Returns (start arc, start param, end param, converged,
    |Φ - Ω| at the start).
    """
    p, lap = table.param_at(np.concatenate([sigma, sigma + length]))
    both = p + lap * part.n_knots
    k = sigma.size
    return polish(
        part._dcols,
        part._theta_nodes,
        part._sig_nodes,
        part.cells_per_piece,
        part.perimeter,
        both[:k],
        both[k:],
        length,
        turn,
        tol,
        max_iter,
    )


# ------------------------------------------------------------------ checks
def _check_query(part: Part, length: float, turn: float, direction: str, method: str) -> tuple[float, float]:
    if not isinstance(part, Part):
        raise QueryError(f"part must be a localizer.Part (use load_part), got {type(part).__name__}")
    if method not in METHODS:
        raise QueryError(f"unknown method {method!r}; use one of {list(METHODS)}")
    if direction not in DIRECTIONS:
        raise QueryError(f"unknown direction {direction!r}; use one of {list(DIRECTIONS)}")
    try:
        length = float(length)
        turn = float(turn)
    except (TypeError, ValueError):
        raise QueryError(f"length and turn must be numbers, got {length!r} and {turn!r}") from None
    if not np.isfinite(length) or not np.isfinite(turn):
        raise QueryError(f"length and turn must be finite, got length={length!r} mm, turn={turn!r} rad")
    if not 0.0 < length < part.perimeter:
        raise QueryError(
            f"length={length!r} mm is out of range: the contact travel must be in "
            f"(0, perimeter={part.perimeter:.6g}) mm on part {part.name!r}"
        )
    return length, turn


# ------------------------------------------------------------------- solver
@dataclass(frozen=True)
class ExactOptions:
    """The exact solver's settings (:func:`feasible_segments`, ``method="exact"``).

    Attributes
    ----------
    tol : float, mm
        Accuracy of each root's arc position.
    flat_tol : float, rad
        |g| below which a whole cell counts as feasible (a circular stretch).
    double_width : float, mm
        Width below which a cell that cannot be certified is reported as a double root.
    max_cells : int
        Work limit against degenerate queries.
    """

    tol: float = 1e-10
    flat_tol: float = 1e-10
    double_width: float = 1e-7
    max_cells: int = 2_000_000

    def __post_init__(self) -> None:
        for name in ("tol", "flat_tol", "double_width"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} must be a positive number")
        if isinstance(self.max_cells, bool) or not isinstance(self.max_cells, int) or self.max_cells < 1:
            raise QueryError(f"max_cells={self.max_cells!r} must be a whole number ≥ 1")


#: The exact solver's defaults.
EXACT = ExactOptions()


def _solve_ccw(
    part: Part, length: float, turn: float, options: ExactOptions
) -> tuple[np.ndarray, tuple[np.ndarray, ...] | None, np.ndarray, list[tuple[float, float]]]:
    """Roots of g on [0, P) for counter-clockwise travel.

    Returns (simple_roots, double_roots, continua): arrays of start arc
    positions, and a list of (start, span) pairs.
    """
    table = arc_table(part)
    zeros, brackets, doubles, flats, status = cell_pass(
        table.sig,
        table.theta_cols,
        table.kappa_cols,
        table.inv_h,
        table.kappa_slope,
        length,
        turn,
        4.0 * table.theta_error + 1e-14,  # |g - g_table| <= 2 theta_error
        1e-9,  # slack on g' (tabulated κ is ~1e-11 off)
        options.flat_tol,
        options.double_width,
        options.max_cells,
        max(1, (table.sig.size - 1) // _SUPER_CELLS),
    )
    if status == TOO_MANY_CELLS:
        raise QueryError(
            f"the query length={length!r} mm, turn={turn!r} rad is degenerate on part {part.name!r}: g stays "
            f"near zero on too many cells (more than {options.max_cells}); the part is nearly a circular arc "
            "there. Raise flat_tol or max_cells"
        )
    joined = (*brackets[:, :6].T, brackets[:, 6] > 0.0) if len(brackets) else None
    return zeros, joined, doubles, merge_flats(flats, table.perimeter)


def _roots_from_brackets(
    part: Part, table: ArcTable, brackets: tuple[np.ndarray, ...], length: float, turn: float, tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Exact roots in certified single-root brackets.

    The start point is the root of the cubic Hermite interpolant of g on the
    bracket (from g and g' at its ends; ~1e-7 mm off on the trefoil), so the
    exact Newton of :func:`_polish` needs one step and one check. A root that
    does not converge inside its bracket is first refined on the table with a
    safeguarded Newton, then polished again.
    """
    lo, hi, glo, ghi, dlo, dhi, dbl = brackets
    P = part.perimeter
    x0 = hermite_roots(lo, hi, glo, ghi, dlo, dhi)
    lam, ps, pe, ok, res = _polish(part, table, x0, length, turn, tol, max_iter=4)
    inside = np.mod(lam - lo + 1e-9, P) <= hi - lo + 2e-9
    bad = np.flatnonzero(~(ok & inside))
    if bad.size:
        xb = _refine(lambda x: _g_table(table, x, length, turn), lo[bad], hi[bad], glo[bad], ghi[bad], 1e-9)
        lam[bad], ps[bad], pe[bad], ok[bad], res[bad] = _polish(part, table, xb, length, turn, tol)
        # still unsettled: keep the table's root, reported as near-double below
        lam[bad] = np.where(ok[bad], lam[bad], xb)
    return lam, ps, pe, ok & ~dbl, res


def _refine(
    fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    lo: np.ndarray,
    hi: np.ndarray,
    glo: np.ndarray,
    ghi: np.ndarray,
    tol: float,
) -> np.ndarray:
    """Safeguarded Newton on bracketed roots, all at once, to ``tol`` mm.

    A Newton step that leaves the bracket is replaced by the secant of the
    bracket (regula falsi), and that by bisection if it stalls.
    """
    lo, hi, glo, ghi = lo.copy(), hi.copy(), glo.copy(), ghi.copy()
    with np.errstate(divide="ignore", invalid="ignore"):
        x: np.ndarray = lo - glo * (hi - lo) / (ghi - glo)
    x = np.where(np.isfinite(x) & (x > lo) & (x < hi), x, 0.5 * (lo + hi))
    active = np.ones(x.shape, bool)
    for _ in range(100):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        xi = x[idx]
        g, dg = fun(xi)
        left = np.sign(g) == np.sign(glo[idx])
        lo[idx] = np.where(left, xi, lo[idx])
        glo[idx] = np.where(left, g, glo[idx])
        hi[idx] = np.where(left, hi[idx], xi)
        ghi[idx] = np.where(left, ghi[idx], g)
        li, hii, gl, gh = lo[idx], hi[idx], glo[idx], ghi[idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            step = g / dg
            xn = xi - step
            xs = li - gl * (hii - li) / (gh - gl)
        inside = (xn > li) & (xn < hii)
        xs = np.where((xs > li) & (xs < hii) & (np.abs(xs - xi) < 0.5 * (hii - li)), xs, 0.5 * (li + hii))
        xn = np.where(inside, xn, xs)
        # an end of the bracket already within tol of the root (by its Newton step)
        with np.errstate(divide="ignore", invalid="ignore"):
            el, eh = np.abs(gl / dg), np.abs(gh / dg)
        near = np.minimum(el, eh) <= tol
        xn = np.where(near, np.where(el <= eh, li, hii), xn)
        done = (g == 0.0) | (hii - li <= tol) | (inside & (np.abs(step) <= tol)) | near
        x[idx] = np.where(g == 0.0, xi, xn)
        active[idx[done]] = False
    return x


def _distinct(x: np.ndarray, P: float, sep: float) -> np.ndarray:
    """Indices of the arc positions ``x`` that stay once those within ``sep`` mm are merged.

    Sorted by position in [0, P); the first of a run of close positions stays,
    across σ = 0 too.
    """
    if x.size < 2:
        return np.arange(x.size)
    xm = np.mod(x, P)
    order: np.ndarray = np.argsort(xm, kind="stable")
    xs = xm[order]
    gaps = np.diff(xs)
    if gaps.min() > sep and xs[0] + P - xs[-1] > sep:  # the usual case: nothing to merge
        return order
    keep = np.concatenate([[True], gaps > sep])
    if keep.sum() > 1 and xs[0] + P - xs[np.flatnonzero(keep)[-1]] <= sep:
        keep[np.flatnonzero(keep)[-1]] = False
    kept: np.ndarray = order[keep]
    return kept


def feasible_segments(
    part: Part | Outline,
    length: float,
    turn: float,
    *,
    method: str = "exact",
    direction: str = "ccw",
    exact: ExactOptions = EXACT,
    marching: MarchOptions = PAPER_MARCH,
) -> list[Segment]:
    """Every boundary segment with arc length ``length`` and total curvature ``turn``.

    Parameters
    ----------
    part : Part or Outline
        The part, from :func:`load_part`. An outline from CAD is solved by
        :func:`localizer.outline_segments` (exact on lines and arcs, corners and continua
        included); the marching reference runs on splines only.
    length : float, mm
        Contact travel L on the jaw (= arc length on the part, eq. 3), ``0 < L < perimeter``.
    turn : float, rad
        Signed jaw rotation Ω, counter-clockwise positive (eq. 4). Rolling
        counter-clockwise over a convex stretch gives Ω > 0; a negative Ω with
        counter-clockwise travel is legal across a concave stretch.
    method : {"exact", "march"}
        Solver. ``"exact"`` is complete by construction (see module notes).
        ``"march"`` is the paper's marching algorithm (:func:`localizer.march`),
        kept as the reference; its segments carry ``iterates``.
    direction : {"ccw", "cw"}
        Direction the contact moved on the part. For ``"cw"`` the contact
        moved clockwise from ``start_arc`` to ``end_arc``; rolling clockwise
        over a convex stretch turns the jaw clockwise (Ω < 0).
    exact : ExactOptions
        ``method="exact"``: the roots' accuracy, the flat and double-root thresholds, the work limit.
    marching : MarchOptions
        ``method="march"``: the integration step h, the tolerances and the separation of starts
        (default: the paper's, :data:`localizer.PAPER_MARCH`).

    Returns
    -------
    list of Segment
        Sorted by ``start_arc``; empty when no segment has that turn.

    Raises
    ------
    QueryError
        ``length`` not in (0, perimeter), non-finite arguments, an unknown
        method or direction, or a degenerate query beyond ``exact.max_cells``.

    Examples
    --------
    >>> import numpy as np
    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    >>> ellipse = part_from_points(np.c_[40 * np.cos(a), 25 * np.sin(a)])
    >>> segs = feasible_segments(ellipse, 20.0, 0.5)
    >>> len(segs)  # by symmetry the roots come in pairs
    4
    >>> [round(s.start_arc, 3) for s in segs]
    [15.425, 68.04, 118.891, 171.506]
    >>> abs(segs[2].start_arc - segs[0].start_arc - ellipse.perimeter / 2) < 1e-9
    True
    """
    if isinstance(part, Outline):
        if method != "exact":
            raise QueryError(
                f"method={method!r}: on an outline from CAD ({part.name}) only the exact solver runs "
                "(localizer.outline_segments); the marching reference is for splines"
            )
        return outline_segments(part, length, turn, direction=direction)
    length, turn = _check_query(part, length, turn, direction, method)
    P = part.perimeter
    omega = turn if direction == "ccw" else -turn
    if method == "march":
        marched = march(part, length, omega, marching)
        if direction == "ccw":
            return [replace(g, turn=turn) for g in marched.segments]
        # the ccw stretch was travelled from its far end
        return sorted(
            (
                replace(
                    g,
                    start_arc=g.end_arc,
                    end_arc=g.start_arc,
                    start_param=g.end_param,
                    end_param=g.start_param,
                    turn=turn,
                    direction="cw",
                )
                for g in marched.segments
            ),
            key=lambda g: g.start_arc,
        )
    zeros, brackets, doubles, continua = _solve_ccw(part, length, omega, exact)
    tol, double_width = exact.tol, exact.double_width
    table = arc_table(part)
    # columns, ccw sense: start arc, kind code, span, residual, start param, end param
    found = []
    if zeros.size:
        found.append(_polish(part, table, zeros, length, omega, tol))
    if brackets is not None:
        found.append(_roots_from_brackets(part, table, brackets, length, omega, tol))
    if found:
        lam, ps, pe, ok, res = (np.concatenate(c) for c in zip(*found))
        keep = _distinct(lam, P, 2 * tol)  # a root on a cell boundary is found from both sides
        lam, ps, pe, res = lam[keep], ps[keep], pe[keep], res[keep]
        # a root the exact Newton cannot settle is ill-conditioned (g' ~ 0): near-double
        code = np.where(ok[keep], 0, 1)
    else:
        lam = ps = pe = res = np.empty(0)
        code = np.empty(0, dtype=int)
    span = np.zeros(lam.size)
    doubles = doubles[_distinct(doubles, P, 10 * double_width)]
    if lam.size and doubles.size:  # a double root already bracketed as a simple one
        near = np.abs(part.arc_offset(doubles[:, None], lam[None, :])).min(axis=1)
        doubles = doubles[near > 10 * double_width]
    for c0, sp0 in continua:  # a touching point inside a continuum is part of it
        doubles = doubles[np.mod(doubles - c0 + 10 * double_width, P) > sp0 + 20 * double_width]
    if doubles.size or continua:
        sig = np.mod(np.concatenate([doubles, [c[0] for c in continua]]), P)
        g, _, ts, te = _g_exact(part, sig, length, omega)
        lam, ps, pe, res = (np.concatenate(x) for x in ((lam, sig), (ps, ts), (pe, te), (res, np.abs(g))))
        code = np.concatenate([code, np.ones(doubles.size, int), np.full(len(continua), 2)])
        span = np.concatenate([span, np.zeros(doubles.size), [c[1] for c in continua]])
    if lam.size == 0:
        return []
    if direction == "ccw":
        sa, ea, sp, ep = lam, lam + length, ps, pe
    else:  # the ccw stretch [s0, s0 + L] was travelled from its far end; a continuum from its far end too
        sa, ea, sp, ep = lam + length + span, lam + span, pe, ps
    order = np.argsort(part.wrap_arc(sa), kind="stable")
    n = part.n_knots
    cols = (part.wrap_arc(sa), part.wrap_arc(ea), np.mod(sp, n), np.mod(ep, n), span, res)
    sa, ea, sp, ep, span, res = (c[order].tolist() for c in cols)
    kinds = [KINDS[k] for k in code[order]]
    return [
        Segment(
            start_arc=sa[i],
            end_arc=ea[i],
            start_param=sp[i],
            end_param=ep[i],
            length=length,
            turn=turn,
            direction=direction,
            kind=kinds[i],
            span=span[i],
            residual=res[i],
        )
        for i in range(len(sa))
    ]

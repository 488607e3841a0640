"""The exact solver's compiled kernels (numba): the cell pass, the Hermite starts and the exact Newton.

The cell pass applies the certificates of :func:`localizer.solve._certify.certify_cells` (module notes
there) to cells that each span ``group`` whole table cells at their start: g and g' are evaluated
at the cells' ends, and the largest |dκ/dσ| bound over the table cells of the start and over those
its end sweeps bounds |g''| on the cell (κ of the table is continuous, so g' is Lipschitz with that
constant across table nodes too). A cell the certificates cannot settle is bisected depth-first on
a stack, so bisection costs no more than the evaluations it makes.

Why compiled: in numpy the pass cost a dozen array calls per bisection round and per table lookup,
and the polish as many per Newton step, on arrays of a few dozen; that overhead, not arithmetic, was
a query's cost (2.5 ms on a traced-like outline of 2880 table cells, 1.2 ms on the trefoil).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._types import BoolArray, FloatArray
from ..geometry import TWO_PI, gauss_legendre

__all__ = ["cell_pass", "hermite_roots", "polish", "TOO_MANY_CELLS"]


#: ``cell_pass`` status: more than ``max_cells`` cells were processed (a nearly circular stretch).
TOO_MANY_CELLS = 1


@numba.njit(cache=True)
def _locate(sig: FloatArray, ss: float, hint: int) -> int:
    """The table cell c with sig[c] <= ss < sig[c + 1] (ss in [0, P)), walking from cell ``hint``: O(1)
    when successive positions are close, as in the sweep; a binary search otherwise."""
    last = sig.size - 2
    c = min(max(hint, 0), last)
    for _ in range(8):
        if ss < sig[c]:
            if c == 0:
                return 0
            c -= 1
        elif c < last and ss >= sig[c + 1]:
            c += 1
        else:
            return c
    lo = 0
    hi = last
    while lo < hi:  # the last cell whose start is <= ss
        mid = (lo + hi + 1) // 2
        if sig[mid] <= ss:
            lo = mid
        else:
            hi = mid - 1
    return lo


@numba.njit(cache=True, error_model="numpy")
def _theta_kappa(
    sig: FloatArray, thc: FloatArray, kac: FloatArray, inv_h: FloatArray, perimeter: float, s: float, hint: int
) -> tuple[float, float, int]:
    """Tabulated θ (rad, unwrapped), κ (1/mm) and the table cell at one unrolled arc position (mm)."""
    lap = math.floor(s / perimeter)
    ss = s - lap * perimeter
    c = _locate(sig, ss, hint)
    x = (ss - sig[c]) * inv_h[c]
    th = thc[5, c]
    for k in range(4, -1, -1):
        th = th * x + thc[k, c]
    ka = kac[4, c]
    for k in range(3, -1, -1):
        ka = ka * x + kac[k, c]
    return th + TWO_PI * lap, ka, c


@numba.njit(cache=True)
def _grow(a: FloatArray) -> FloatArray:
    out = np.empty((2 * a.shape[0], a.shape[1]))
    out[: a.shape[0]] = a
    return out


@numba.njit(cache=True)
def _put(
    rows: FloatArray, n: int, a: float, b: float, ga: float, gb: float, da: float, db: float, last: float
) -> FloatArray:
    """``rows`` (grown when full) with row ``n`` set to a cell: its ends (mm), g and g' there, and ``last``."""
    if n == rows.shape[0]:
        rows = _grow(rows)
    rows[n, 0] = a
    rows[n, 1] = b
    rows[n, 2] = ga
    rows[n, 3] = gb
    rows[n, 4] = da
    rows[n, 5] = db
    rows[n, 6] = last
    return rows


@numba.njit(cache=True, error_model="numpy")
def cell_pass(
    sig: FloatArray,
    thc: FloatArray,
    kac: FloatArray,
    inv_h: FloatArray,
    slope: FloatArray,
    length: float,
    turn: float,
    margin: float,
    dmargin: float,
    flat_tol: float,
    double_width: float,
    max_cells: int,
    group: int,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, int]:
    """Certify every cell of g(σ) = θ(σ + L) − θ(σ) − Ω on [0, P) for counter-clockwise travel.

    Parameters
    ----------
    sig : ndarray (J+1,), mm
        The table's cell boundaries (``sig[-1]`` is the perimeter P).
    thc, kac : ndarray (6, J), (5, J)
        θ and κ of each table cell as polynomials in the cell's unit coordinate, column by column.
    inv_h, slope : ndarray (J,)
        1 / cell width (1/mm) and the bound of |dκ/dσ| on each cell (1/mm²).
    length, turn : float
        L (mm, 0 < L < P) and Ω (rad).
    margin, dmargin, flat_tol, double_width : float
        As :func:`localizer.solve._certify.certify_cells`.
    max_cells : int
        Most cells processed before the query is called degenerate.
    group : int
        Table cells per starting cell (≥ 1).

    Returns
    -------
    zeros : ndarray (n,)
        Cell ends where g is exactly 0, mm.
    brackets : ndarray (m, 7)
        Single-root brackets: lo, hi (mm), g there (rad), g' there (1/mm), near-double flag (0/1).
    doubles : ndarray (d,)
        Double-root positions, mm.
    flats : ndarray (f, 2)
        Flat cells (start, end), mm, unmerged.
    status : int
        0, or :data:`TOO_MANY_CELLS`.
    """
    J = sig.size - 1
    P = sig[J]
    m = (J + group - 1) // group
    # g, g' at the super cells' starts (table nodes) and the table cell of each end
    bp = np.empty(m + 1)
    g = np.empty(m + 1)
    dg = np.empty(m + 1)
    ce = np.empty(m + 1, np.int64)
    hint = 0
    for r in range(m + 1):
        i = min(r * group, J)
        th_e, k_e, c_e = _theta_kappa(sig, thc, kac, inv_h, P, sig[i] + length, hint)
        hint = c_e
        bp[r] = sig[i]
        j = min(i, J - 1)
        th0 = thc[0, j] if i < J else thc[0, 0] + TWO_PI
        g[r] = th_e - th0 - turn
        dg[r] = k_e - kac[0, j if i < J else 0]
        ce[r] = c_e
    # g is periodic: at P it is g at 0, taken once. Evaluated again through the wrap (θ + 2π on both
    # terms) it differs by a rounding, and a root at the seam itself, where g(0) is a rounding from zero,
    # fell between the two: neither the last cell nor the first saw a sign change
    g[m] = g[0]
    dg[m] = dg[0]
    nz = 0
    zbuf = np.empty(m + 1)
    brackets = np.empty((64, 7))
    nb = 0
    dbuf = np.empty(16)
    nd = 0
    flats = np.empty((16, 2))
    nf = 0
    stack = np.empty((128, 7))
    processed = 0
    for r in range(m):
        if g[r] == 0.0:
            zbuf[nz] = bp[r]
            nz += 1
        # |κ'| bounds over the start's table cells and over those the end sweeps (cyclically)
        K_s = 0.0
        for c in range(r * group, min((r + 1) * group, J)):
            K_s = max(K_s, slope[c])
        K_e = 0.0
        c = ce[r]
        while True:
            K_e = max(K_e, slope[c])
            if c == ce[r + 1]:
                break
            c = c + 1 if c + 1 < J else 0
        stack = _put(stack, 0, bp[r], bp[r + 1], g[r], g[r + 1], dg[r], dg[r + 1], K_s + K_e)
        top = 1
        hs = r * group
        he = ce[r]
        while top > 0:
            top -= 1
            a = stack[top, 0]
            b = stack[top, 1]
            ga = stack[top, 2]
            gb = stack[top, 3]
            da = stack[top, 4]
            db = stack[top, 5]
            K = stack[top, 6]
            processed += 1
            if processed > max_cells:
                return zbuf[:0].copy(), brackets[:0].copy(), dbuf[:0].copy(), flats[:0].copy(), TOO_MANY_CELLS
            w = b - a
            s = da + db
            mono = (s > K * w + dmargin) or (s < -(K * w + dmargin))
            change = ga * gb < 0.0
            if mono:
                if change:
                    brackets = _put(brackets, nb, a, b, ga, gb, da, db, 0.0)
                    nb += 1
                continue
            # same-sign ends: no root if the quadratic envelopes' zero crossings overlap
            sg = np.sign(ga) if ga != 0.0 else np.sign(gb)
            Ga = sg * ga - margin
            Gb = sg * gb - margin
            Da = sg * da
            Db = sg * db
            ra = (Da + math.sqrt(max(Da * Da + 2 * K * Ga, 0.0))) / K
            rb = (-Db + math.sqrt(max(Db * Db + 2 * K * Gb, 0.0))) / K
            if (not change) and Ga > 0 and Gb > 0 and ra + rb > w:
                continue
            M = 0.5 * (abs(s) + K * w)
            if max(abs(ga), abs(gb)) + 0.5 * M * w + margin <= flat_tol:
                if nf == flats.shape[0]:
                    flats = _grow(flats)
                flats[nf, 0] = a
                flats[nf, 1] = b
                nf += 1
                continue
            if w <= double_width:
                if change:
                    brackets = _put(brackets, nb, a, b, ga, gb, da, db, 1.0)
                    nb += 1
                else:
                    if nd == dbuf.size:
                        grown = np.empty(2 * nd)
                        grown[:nd] = dbuf
                        dbuf = grown
                    dbuf[nd] = a if abs(ga) <= abs(gb) else b
                    nd += 1
                continue
            mid = 0.5 * (a + b)
            th_s, k_s, _ = _theta_kappa(sig, thc, kac, inv_h, P, mid, hs)
            th_e, k_e, _ = _theta_kappa(sig, thc, kac, inv_h, P, mid + length, he)
            gm = th_e - th_s - turn
            dm = k_e - k_s
            # the right half below the left, so cells come out in order
            stack = _put(stack, top, mid, b, gm, gb, dm, db, K)
            stack = _put(stack, top + 1, a, mid, ga, gm, da, dm, K)
            top += 2
    return zbuf[:nz].copy(), brackets[:nb].copy(), dbuf[:nd].copy(), flats[:nf].copy(), 0


_GL8_X, _GL8_W = gauss_legendre(8)


@numba.njit(cache=True, error_model="numpy")
def _state(
    dcols: FloatArray, theta_nodes: FloatArray, sig_nodes: FloatArray, per_piece: int, perimeter: float, t: float
) -> tuple[float, float, float, float]:
    """Exact (arc position mm, unwrapped θ rad, κ 1/mm, speed mm per unit parameter) at unrolled ``t``:
    :meth:`localizer.Part.state` for one parameter."""
    n = dcols.shape[1]
    lap = math.floor(t / n)
    tt = t - lap * n
    piece = min(int(tt), n - 1)
    u = tt - piece
    cell = min(int(tt * per_piece), n * per_piece - 1)
    c0, c1, c2 = dcols[0, piece], dcols[1, piece], dcols[2, piece]
    c3, c4, c5 = dcols[3, piece], dcols[4, piece], dcols[5, piece]
    dx = (c2 * u + c1) * u + c0
    dy = (c5 * u + c4) * u + c3
    ddx = 2.0 * c2 * u + c1
    ddy = 2.0 * c5 * u + c4
    base = theta_nodes[cell]
    theta = base + ((math.atan2(dy, dx) - base + math.pi) % TWO_PI - math.pi) + TWO_PI * lap
    u0 = (cell - piece * per_piece) / per_piece
    w = u - u0
    arc = 0.0
    for k in range(_GL8_X.size):
        uk = u0 + w * _GL8_X[k]
        arc += _GL8_W[k] * math.hypot((c2 * uk + c1) * uk + c0, (c5 * uk + c4) * uk + c3)
    v2 = dx * dx + dy * dy
    v = math.sqrt(v2)
    return sig_nodes[cell] + arc * w + perimeter * lap, theta, (dx * ddy - dy * ddx) / (v2 * v), v


@numba.njit(cache=True, error_model="numpy")
def polish(
    dcols: FloatArray,
    theta_nodes: FloatArray,
    sig_nodes: FloatArray,
    per_piece: int,
    perimeter: float,
    ts: FloatArray,
    te: FloatArray,
    length: float,
    turn: float,
    tol: float,
    max_iter: int,
) -> tuple[FloatArray, FloatArray, FloatArray, BoolArray, FloatArray]:
    """Newton on the exact system ℓ(s, e) = L, Φ(s, e) = Ω in the spline parameters, root by root.

    Parameters
    ----------
    dcols, theta_nodes, sig_nodes, per_piece, perimeter
        The spline's derivative coefficients (6, N), θ (rad) and arc position (mm) at its table
        nodes, table cells per piece, perimeter (mm).
    ts, te : ndarray
        Unrolled starting parameters of each root's start and end.
    length, turn, tol : float
        L (mm), Ω (rad), the accuracy (mm) at which a root is settled.
    max_iter : int
        Most Newton steps.

    Returns
    -------
    arc, ps, pe, ok, residual : ndarray
        Start arc positions (mm, unrolled), start and end parameters, whether the last correction
        was below ``tol`` (then the start is known to ``tol``: Newton's error after a step is
        quadratic in it), and |Φ − Ω| (rad).
    """
    k = ts.size
    arc = np.empty(k)
    ps = ts.copy()
    pe = te.copy()
    ok = np.zeros(k, np.bool_)
    res = np.empty(k)
    for i in range(k):
        for it in range(max_iter + 1):
            ls, ths, ks, vs = _state(dcols, theta_nodes, sig_nodes, per_piece, perimeter, ps[i])
            le, the, ke, ve = _state(dcols, theta_nodes, sig_nodes, per_piece, perimeter, pe[i])
            f1 = le - ls - length
            f2 = the - ths - turn
            dss = (ke * f1 - f2) / (ke - ks)
            arc[i] = ls
            res[i] = abs(f2)
            ok[i] = abs(dss) + abs(f1) <= tol  # False when g' = 0 made the step inf or nan
            if ok[i] or it == max_iter or not math.isfinite(dss):
                break
            ps[i] += dss / vs
            pe[i] += (dss - f1) / ve
    return arc, ps, pe, ok, res


@numba.njit(cache=True, error_model="numpy")
def hermite_roots(
    lo: FloatArray, hi: FloatArray, glo: FloatArray, ghi: FloatArray, dlo: FloatArray, dhi: FloatArray
) -> FloatArray:
    """A start for each bracket's root: the root of the cubic Hermite through g and g' at its ends.

    Newton on the cubic from the secant point, two steps, kept inside the bracket (~1e-7 mm off on
    the trefoil, so the exact Newton of :func:`polish` needs one step and one check).

    Parameters
    ----------
    lo, hi, glo, ghi, dlo, dhi : ndarray
        Bracket ends (mm) with g (rad, opposite signs) and g' (1/mm) there.

    Returns
    -------
    ndarray, mm
    """
    out = np.empty(lo.size)
    for i in range(lo.size):
        w = hi[i] - lo[i]
        g0, g1, d0, d1 = glo[i], ghi[i], dlo[i] * w, dhi[i] * w
        c2 = 3.0 * (g1 - g0) - 2.0 * d0 - d1
        c3 = 2.0 * (g0 - g1) + d0 + d1
        x = g0 / (g0 - g1)
        for _ in range(2):
            f = ((c3 * x + c2) * x + d0) * x + g0
            x = x - f / ((3.0 * c3 * x + 2.0 * c2) * x + d0)
        x = min(max(x, 0.0), 1.0) if math.isfinite(x) else 0.5
        out[i] = lo[i] + w * x
    return out

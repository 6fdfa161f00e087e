"""Influence matrix of the axisymmetric surface displacement (paper eq. 4, 12).

The displacement integral of eq. (4),

    W(r) = integral_0^{r_m} t / (t + r) K(m) P(t) dt,   m = 4 t r / (t + r)^2,

applied to the piecewise-linear pressure of eq. (11) gives the matrix of
eq. (12), ``A[i, j] = W(r_i)`` for ``P = phi_j``, the hat function of node j.
The integrand has a logarithmic singularity at t = r_i (m -> 1); its only
other singularity, t = -r_i, is farther from every element than t = r_i.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.polynomial.legendre import leggauss, legval
from scipy.special import ellipk, ellipkm1

if TYPE_CHECKING:
    from petsc4py import PETSc

__all__ = ["influence_rows", "create_influence"]


def _gauss01(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = leggauss(n)
    return (x + 1) / 2, w / 2


def _log_correction(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """c with  sum_q (w_q ln(x_q) + c_q) f(x_q) = int_0^1 ln(x) f(x) dx.

    Exact for polynomials f of degree < len(x), from the moments
    int_0^1 ln(x) Pt_k(x) dx of the shifted Legendre polynomials Pt_k:
    -1 for k = 0 and (-1)^(k+1) / (k (k + 1)) for k > 0.
    """
    k = np.arange(x.size)
    moments = np.append(-1.0, (-1.0) ** (k[1:] + 1) / (k[1:] * (k[1:] + 1)))
    return w * (legval(2 * x - 1, (2 * k + 1) * moments) - np.log(x))


# Gauss-Legendre points for a piece at q = distance(r_i, piece) / length,
# from Bernstein-ellipse estimates, then checked against 20-point rules on
# whole matrices: entries agree to 5e-13 relative, 3e-15 of the row maximum.
# Pieces with q < _Q_SPLIT are cut first (see _split).
_TIERS = ((3.0, 16), (20.0, 6), (100.0, 4), (np.inf, 3))
_GAUSS = {n: _gauss01(n) for _, n in _TIERS}
_Q_SPLIT = 0.5
_XLOG, _WLOG = _gauss01(16)
_CLOG = _log_correction(_XLOG, _WLOG)
# bounds the temporaries: about this many integrand values per row block
_BLOCK_EVALS = 4_000_000


def _regular(rr: np.ndarray, c: np.ndarray, ell: np.ndarray,
             u0: np.ndarray, du: np.ndarray,
             q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Left- and right-hat integrals over pieces [c, c + ell] not touching rr.

    ``u0 + du * x`` is the right hat of the piece's element at t = c + ell x
    (the left hat is one minus it); ``q`` picks the tier of each piece.
    """
    left, right = np.empty_like(c), np.empty_like(c)
    # the integrand vanishes like t at t = 0, so on [0, r_1] the error
    # relative to the entry is about q times that elsewhere
    q = np.where(c > 0, q, 0.0)
    lower = 0.0
    for upper, n in _TIERS:
        sel = np.flatnonzero((q >= lower) & (q < upper))
        lower = upper
        x, w = _GAUSS[n]
        r = rr[sel]
        # points along axis 0: numpy's inner loops then run over the pieces
        t = c[sel] + ell[sel] * x[:, None]
        tr = t + r
        s = (t - r) / tr
        # 1 - m as s^2 keeps K's digits where t is close to r
        f = t / tr * ellipkm1(s * s)
        f0, f1 = w @ f, (w * x) @ f
        right[sel] = ell[sel] * (u0[sel] * f0 + du[sel] * f1)
        left[sel] = ell[sel] * f0 - right[sel]
    return left, right


def _split(rr: np.ndarray, c: np.ndarray, ell: np.ndarray,
           u0: np.ndarray, du: np.ndarray,
           dist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`_regular` for pieces longer than twice their distance ``dist`` to rr.

    Where the grid spacing jumps, no affordable Gauss rule reaches round-off
    on such a piece; cut at distances dist (2^k - 1) from its end nearest rr,
    every sub-piece is at least its own length away from rr.
    """
    nsub = np.ceil(np.log2(1 + ell / dist)).astype(int)
    parent = np.repeat(np.arange(c.size), nsub)
    k = np.arange(parent.size) - np.repeat(np.cumsum(nsub) - nsub, nsub)
    d, e = dist[parent], ell[parent]
    lo = np.minimum(d * (2.0 ** k - 1), e)
    hi = np.where(k == nsub[parent] - 1, e,
                  np.minimum(d * (2.0 ** (k + 1) - 1), e))
    start = np.where(rr[parent] < c[parent], lo, e - hi)
    left, right = _regular(rr[parent], c[parent] + start, hi - lo,
                           u0[parent] + du[parent] * start / e,
                           du[parent] * (hi - lo) / e,
                           # rounding may leave an empty last sub-piece
                           (d + lo) / np.maximum(hi - lo, d))
    return (np.bincount(parent, left, c.size),
            np.bincount(parent, right, c.size))


def _touching(r: np.ndarray, length: np.ndarray, a: np.ndarray,
              h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Left- and right-hat integrals over [r, r + length] (length may be < 0).

    K(m) = A(m1) - ln(m1) K(m1) / pi with m1 = 1 - m, A analytic, and
    ln(m1) = 2 ln|t - r| - 2 ln(t + r): the integrand is analytic plus
    ln|t - r| times -(2/pi) t / (t + r) K(m1) phi(t), so Gauss-Legendre with
    the product-rule correction of the log term converges fast.
    The analytic parts are singular at t = 0, which the caller keeps at
    least |length| away.
    """
    r = r[:, None]
    t = r + length[:, None] * _XLOG
    s = (t - r) / (t + r)
    m1 = s * s
    g = t / (t + r) * (_WLOG * ellipkm1(m1) - 2 / np.pi * _CLOG * ellipk(m1))
    right = np.abs(length) * np.sum(g * (t - a[:, None]), axis=1) / h
    return np.abs(length) * g.sum(axis=1) - right, right


def _add_rows(r: np.ndarray, lo: int, out: np.ndarray) -> None:
    """Add rows lo, lo + 1, ... (all with r > 0) of A to ``out``."""
    n = r.size
    a, h = r[:-1], np.diff(r)
    rows = np.arange(lo, lo + out.shape[0])
    below = np.arange(rows.size)                    # element i - 1 ends at r_i
    above = np.flatnonzero(rows < n - 1)            # element i starts at r_i
    el_below, el_above = rows[below] - 1, rows[above]
    # the log rule takes the part of these two elements next to r_i, short
    # enough to stay its own length away from t = 0
    len_below = h[el_below] / 2
    len_above = np.minimum(h[el_above] / 2, r[el_above])

    # one regular piece per (row, element): the element less that part
    c = np.repeat(a[None], rows.size, axis=0)
    ell = np.repeat(h[None], rows.size, axis=0)
    ell[below, el_below] -= len_below
    c[above, el_above] += len_above
    ell[above, el_above] -= len_above
    ri = r[rows, None]
    dist = np.maximum(c - ri, ri - c - ell).ravel()
    piece = (np.repeat(r[rows], n - 1), c.ravel(), ell.ravel(),
             ((c - a) / h).ravel(), (ell / h).ravel())
    q = dist / piece[2]
    left, right = _regular(*piece, q)
    # the few pieces too close to r_i are redone, which beats masking all
    cut = np.flatnonzero(q < _Q_SPLIT)
    rr, cc, ll, u0, du = (v[cut] for v in piece)
    left[cut], right[cut] = _split(rr, cc, ll, u0, du, dist[cut])
    out[:, :-1] += left.reshape(c.shape)
    out[:, 1:] += right.reshape(c.shape)

    tr = np.concatenate([below, above])
    te = np.concatenate([el_below, el_above])
    tleft, tright = _touching(r[rows[tr]],
                              np.concatenate([-len_below, len_above]),
                              a[te], h[te])
    # each (row, element) pair occurs once here: += cannot collide
    out[tr, te] += tleft
    out[tr, te + 1] += tright


def influence_rows(r: np.ndarray, start: int, stop: int) -> np.ndarray:
    """Rows ``start`` to ``stop - 1`` of the influence matrix of eq. (12).

    Parameters
    ----------
    r : numpy.ndarray
        Sorted nodes, ``0 = r[0] < r[1] < ... < r[-1] = r_m``.
    start, stop : int
        Row range, ``0 <= start <= stop <= len(r)``.

    Returns
    -------
    numpy.ndarray
        ``A[start:stop]``, shape ``(stop - start, len(r))``, where
        ``A[i, j] = integral_0^{r_m} t / (t + r_i) K(m) phi_j(t) dt`` is the
        displacement of eq. (4) at ``r_i`` due to the hat ``phi_j`` of node j.
    """
    r = np.asarray(r, dtype=float)
    n = r.size
    out = np.zeros((stop - start, n))
    first = start
    if start == 0 < stop:
        # r = 0: m = 0, so the integrand is (pi / 2) phi_j
        h = np.diff(r)
        out[0, :-1] += np.pi / 4 * h
        out[0, 1:] += np.pi / 4 * h
        first = 1
    block = max(1, _BLOCK_EVALS // (4 * n))
    for lo in range(first, stop, block):
        _add_rows(r, lo, out[lo - start:min(lo + block, stop) - start])
    return out


def create_influence(r: np.ndarray,
                     comm: PETSc.Comm | None = None) -> PETSc.Mat:
    """The influence matrix of eq. (12) as a row-distributed dense PETSc Mat.

    Parameters
    ----------
    r : numpy.ndarray
        Sorted nodes, ``0 = r[0] < ... < r[-1] = r_m``, the same on all ranks.
    comm : petsc4py.PETSc.Comm, optional
        Communicator, ``PETSc.COMM_WORLD`` by default.

    Returns
    -------
    petsc4py.PETSc.Mat
        Assembled dense ``N x N`` matrix of eq. (12) (eq. 4 on the hats of
        eq. 11) in PETSc's default row layout; each rank computes only the
        rows it owns.
    """
    from petsc4py import PETSc

    n = len(r)
    A = PETSc.Mat().createDense(size=((None, n), (None, n)),
                                comm=PETSc.COMM_WORLD if comm is None else comm)
    A.setUp()
    start, stop = A.getOwnershipRange()
    A.setValues(np.arange(start, stop, dtype=PETSc.IntType),
                np.arange(n, dtype=PETSc.IntType),
                influence_rows(r, start, stop))
    A.assemble()
    return A

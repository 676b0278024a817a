"""Compiled closest-point contact kinematics: projection, gap, gradient and Hessian per pair.

The same mechanics as the NumPy path of :mod:`sandwich.beam.contact_projection` (its module
docstring has the equations; ``closest_point_kinematics_numpy`` there is the reference this
kernel is tested against), in one loop over pairs with scalar work per candidate segment: the
projection Newton φ(ξ) = r·X_ξ = 0 on every searched segment (each candidate stops on its own
|Δξ| < tol, where the NumPy path iterates all of them until the slowest settles: the same ξ to
round-off), the choice of the nearest projection on a segment (else the nearer end of the
searched stretch), and on the chosen segment the gap g̃ = n·r with its derivatives in
y = (ξ, q): J, Z, the implicit ξ_q = −φ_q/φ_ξ and

    ∂g/∂q = g̃_q,    ∂²g/∂q² = g̃_qq + g̃_qξ ⊗ ξ_q + ξ_q ⊗ g̃_ξq + g̃_ξξ ξ_q ⊗ ξ_q.

No per-call allocation beyond the outputs.
"""

from __future__ import annotations

import numpy as np

from sandwich.solver.jit import njit


@njit
def _hermite(ξ, l, out):  # pragma: no cover - compiled
    """Cubic Hermite functions on [0, 1] and their ξ-derivatives 0 … 3 into ``out`` (4, 4)."""
    ξ2 = ξ * ξ
    ξ3 = ξ2 * ξ
    out[0, 0] = 1 - 3 * ξ2 + 2 * ξ3
    out[0, 1] = l * (ξ - 2 * ξ2 + ξ3)
    out[0, 2] = 3 * ξ2 - 2 * ξ3
    out[0, 3] = l * (ξ3 - ξ2)
    out[1, 0] = 6 * (ξ2 - ξ)
    out[1, 1] = l * (1 - 4 * ξ + 3 * ξ2)
    out[1, 2] = -out[1, 0]
    out[1, 3] = l * (3 * ξ2 - 2 * ξ)
    out[2, 0] = 12 * ξ - 6
    out[2, 1] = l * (6 * ξ - 4)
    out[2, 2] = -out[2, 0]
    out[2, 3] = l * (6 * ξ - 2)
    out[3, 0] = 12.0
    out[3, 2] = -12.0
    out[3, 1] = 6 * l
    out[3, 3] = 6 * l


@njit
def _dot4(a, b):  # pragma: no cover - compiled
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]


@njit
def _segment(x, values, node, Us, Ws):  # pragma: no cover - compiled
    """The segment from core node ``node`` to the next: its start x and length, (U, W) filled."""
    xa = x[node]
    ls = x[node + 1] - xa
    Us[0], Us[1], Us[2], Us[3] = values[node, 0], values[node, 1], values[node + 1, 0], \
        values[node + 1, 1]
    Ws[0], Ws[1], Ws[2], Ws[3] = values[node, 2], values[node, 3], values[node + 1, 2], \
        values[node + 1, 3]
    return xa, ls


@njit
def _hull_boxes(x, values, Us, Ws):  # pragma: no cover - compiled
    """Bounding box (lo_x, hi_x, lo_z, hi_z) of every core segment's Bézier control points.

    The cubic Hermite curve of the segment from node j to j + 1 lies in the convex hull of its
    Bézier control points P0, P0 + (l/3) X_x(0), P1 − (l/3) X_x(1), P1; the distance from a
    point to their bounding box bounds the distance to the curve from below. A box belongs to
    the segment, not to a pair: formed once per call for all pairs.
    """
    boxes = np.empty((max(x.size - 1, 0), 4))
    for j in range(x.size - 1):
        xa, ls = _segment(x, values, j, Us, Ws)
        x0, z0 = xa + Us[0], Ws[0]
        x3, z3 = xa + ls + Us[2], Ws[2]
        x1, z1 = x0 + ls / 3 * (1 + Us[1]), z0 + ls / 3 * Ws[1]
        x2, z2 = x3 - ls / 3 * (1 + Us[3]), z3 - ls / 3 * Ws[3]
        boxes[j, 0] = min(min(x0, x1), min(x2, x3))
        boxes[j, 1] = max(max(x0, x1), max(x2, x3))
        boxes[j, 2] = min(min(z0, z1), min(z2, z3))
        boxes[j, 3] = max(max(z0, z1), max(z2, z3))
    return boxes


@njit
def _box_distance_sq(boxes, j, px, pz):  # pragma: no cover - compiled
    """Squared distance from (px, pz) to segment j's box (a lower bound for the curve's)."""
    lo_x, hi_x, lo_z, hi_z = boxes[j, 0], boxes[j, 1], boxes[j, 2], boxes[j, 3]
    dx = lo_x - px if px < lo_x else (px - hi_x if px > hi_x else 0.0)
    dz = lo_z - pz if pz < lo_z else (pz - hi_z if pz > hi_z else 0.0)
    return dx * dx + dz * dz


#: A box is passed over when its squared distance exceeds the best projection's by more than
#: this (relative): far above the rounding of the two, so no segment that could tie is skipped.
BOX_MARGIN = 1e-10


@njit
def closest_point_kernel(x, values, core_nodes, xs, ws, x_node, valid, s_n, tol, max_iter,
                         res_tol, seg_tol):  # pragma: no cover - compiled
    """Kinematics of m pairs over S candidate segments each.

    ``x`` (n,): reference x of the core boundary nodes; ``values`` (n, 4): their (u, u_x, w,
    w_x); ``core_nodes`` (m, S + 1): each pair's window of nodes, segment s joining
    ``core_nodes[p, s]`` and the next node where ``valid[p, s]``; ``xs``, ``ws`` (m,): the
    master points; ``x_node`` (m,): the pairs' node x. Candidates are searched nearest box
    first (the distance to the control points' box, a lower bound of the distance to the
    segment, :func:`_hull_boxes`), and the search stops at the first box farther than the best
    projection found: no segment left can be nearer. The choice is the nearest projection on a
    segment, the lowest segment on a tie — the NumPy path's ``argmin``, whichever order the
    candidates are searched in (every segment that could tie is searched). The work per pair
    is one pass over its window's boxes plus a projection per searched segment, and nothing is
    gathered per window (fig. 5 at 7680 elements: 4961 pairs × 250 segments).
    Returns gap (m,), grad (m, 10), hess (m, 10, 10), cols (m, 10), sliding, ξ, segment,
    outside — the fields of ``sandwich.beam.contact_projection.ChosenSegment``.
    """
    m, S = valid.shape
    gap = np.empty(m)
    grad = np.empty((m, 10))
    hess = np.empty((m, 10, 10))
    cols = np.empty((m, 10), dtype=np.int64)
    sliding = np.empty(m)
    xi_out = np.empty(m)
    seg_out = np.empty(m, dtype=np.int64)
    outside = np.zeros(m, dtype=np.bool_)
    N = np.empty((4, 4))
    J = np.zeros((4, 11))
    H = np.empty((11, 11))
    DJ = np.empty((4, 11))
    dg = np.empty(4)
    d2g = np.empty((4, 4))
    ξq = np.empty(10)
    Us = np.empty(4)
    Ws = np.empty(4)
    boxes = _hull_boxes(x, values, Us, Ws)
    ends = np.empty(2)
    hd = np.empty(S)  # a pair's squared box distances; +inf once searched (or invalid)
    for p in range(m):
        best, best_d, best_ξ = -1, np.inf, 0.0
        first_valid, last_valid = -1, -1
        for s in range(S):
            if valid[p, s]:
                if first_valid < 0:
                    first_valid = s
                last_valid = s
                hd[s] = _box_distance_sq(boxes, core_nodes[p, s], xs[p], ws[p])
            else:
                hd[s] = np.inf
        for _t in range(S):
            s = -1  # the nearest box not yet searched (the lowest segment on a tie)
            lo = np.inf
            for r in range(S):
                if hd[r] < lo:
                    lo = hd[r]
                    s = r
            if s < 0 or (best >= 0 and lo > best_d * best_d * (1.0 + BOX_MARGIN)):
                break
            hd[s] = np.inf
            xas, ls = _segment(x, values, core_nodes[p, s], Us, Ws)
            ξ = min(max((x_node[p] - xas) / ls, 0.0), 1.0)
            for _ in range(max_iter):
                _hermite(ξ, ls, N)
                r1 = xs[p] - (xas + ls * ξ + _dot4(N[0], Us))
                r2 = ws[p] - _dot4(N[0], Ws)
                a, c = ls + _dot4(N[1], Us), _dot4(N[1], Ws)
                φ = r1 * a + r2 * c
                φξ = -(a * a + c * c) + r1 * _dot4(N[2], Us) + r2 * _dot4(N[2], Ws)
                if not (φξ < -1e-3 * (a * a + c * c)):  # keep the descent
                    φξ = -(a * a + c * c)
                step = min(max(-φ / φξ, -0.5), 0.5)
                new = min(max(ξ + step, -0.5), 1.5)
                change = abs(new - ξ)
                ξ = new
                if change < tol:
                    break
            _hermite(ξ, ls, N)
            r1 = xs[p] - (xas + ls * ξ + _dot4(N[0], Us))
            r2 = ws[p] - _dot4(N[0], Ws)
            a, c = ls + _dot4(N[1], Us), _dot4(N[1], Ws)
            φ = r1 * a + r2 * c
            if (abs(φ) <= res_tol * (a * a + c * c) and ξ >= -seg_tol
                    and ξ <= 1 + seg_tol):
                d = np.hypot(r1, r2)
                if d < best_d or (d == best_d and s < best):
                    best, best_d, best_ξ = s, d, ξ
        if best < 0:  # no projection on the searched curve: the nearer end, ξ fixed
            outside[p] = True
            for e, (s, ξe) in enumerate(((first_valid, 0.0), (last_valid, 1.0))):
                xas, ls = _segment(x, values, core_nodes[p, s], Us, Ws)
                _hermite(ξe, ls, N)
                Xe = xas + ls * ξe + _dot4(N[0], Us)
                ends[e] = np.hypot(xs[p] - Xe, ws[p] - _dot4(N[0], Ws))
            if ends[1] < ends[0]:
                best, best_ξ = last_valid, 1.0
            else:
                best, best_ξ = first_valid, 0.0
        s, ξ = best, best_ξ
        xas, ls = _segment(x, values, core_nodes[p, s], Us, Ws)
        _hermite(ξ, ls, N)
        r1 = xs[p] - (xas + ls * ξ + _dot4(N[0], Us))
        r2 = ws[p] - _dot4(N[0], Ws)
        a, c = ls + _dot4(N[1], Us), _dot4(N[1], Ws)
        aξ, cξ = _dot4(N[2], Us), _dot4(N[2], Ws)
        aξξ, cξξ = _dot4(N[3], Us), _dot4(N[3], Ws)
        # gap g = s_n (a r2 − c r1)/ell and its derivatives in z = (r1, r2, a, c)
        ell = np.sqrt(a * a + c * c)
        q = -c * r1 + a * r2
        dq0, dq1, dq2, dq3 = -c, a, r2, -r1
        dl2, dl3 = a / ell, c / ell
        dg[0] = s_n * dq0 / ell
        dg[1] = s_n * dq1 / ell
        dg[2] = s_n * (dq2 / ell - q * dl2 / ell**2)
        dg[3] = s_n * (dq3 / ell - q * dl3 / ell**2)
        dq = (dq0, dq1, dq2, dq3)
        dl = (0.0, 0.0, dl2, dl3)
        for i in range(4):
            for j in range(4):
                d2q = 0.0
                if (i == 0 and j == 3) or (i == 3 and j == 0):
                    d2q = -1.0
                elif (i == 1 and j == 2) or (i == 2 and j == 1):
                    d2q = 1.0
                d2l = 0.0
                if i == 2 and j == 2:
                    d2l = c * c / ell**3
                elif i == 3 and j == 3:
                    d2l = a * a / ell**3
                elif (i == 2 and j == 3) or (i == 3 and j == 2):
                    d2l = -a * c / ell**3
                d2g[i, j] = s_n * (d2q / ell - (dq[i] * dl[j] + dl[i] * dq[j]) / ell**2
                                   - q / ell**2 * d2l + 2 * q / ell**3 * dl[i] * dl[j])
        gap[p] = s_n * q / ell
        # J = ∂(r1, r2, a, c)/∂y, y = (ξ, u_f, w_f, U0..U3, W0..W3)
        J[:, :] = 0.0
        J[0, 0], J[0, 1] = -a, 1.0
        J[1, 0], J[1, 2] = -c, 1.0
        J[2, 0], J[3, 0] = aξ, cξ
        for k in range(4):
            J[0, 3 + k] = -N[0, k]
            J[1, 7 + k] = -N[0, k]
            J[2, 3 + k] = N[1, k]
            J[3, 7 + k] = N[1, k]
        # H = Jᵀ d2g J + Σ_α g̃_α Z_α (Z: the ξ row and column only); explicit sums: BLAS on
        # (4, 11) operands costs more in calls and temporaries than the 660 products
        for k in range(4):
            for j in range(11):
                t = 0.0
                for r in range(4):
                    t += d2g[k, r] * J[r, j]
                DJ[k, j] = t
        for i in range(11):
            for j in range(i, 11):
                t = 0.0
                for k in range(4):
                    t += J[k, i] * DJ[k, j]
                H[i, j] = t
                H[j, i] = t
        H[0, 0] += -dg[0] * aξ - dg[1] * cξ + dg[2] * aξξ + dg[3] * cξξ
        for k in range(4):
            zu = -dg[0] * N[1, k] + dg[2] * N[2, k]
            zw = -dg[1] * N[1, k] + dg[3] * N[2, k]
            H[0, 3 + k] += zu
            H[3 + k, 0] += zu
            H[0, 7 + k] += zw
            H[7 + k, 0] += zw
        # ξ_q = −φ_q/φ_ξ from φ = r1 a + r2 c (zero outside: ξ held at its end)
        Φ0 = a * J[0, 0] + c * J[1, 0] + r1 * J[2, 0] + r2 * J[3, 0]
        for j in range(10):
            Φj = a * J[0, j + 1] + c * J[1, j + 1] + r1 * J[2, j + 1] + r2 * J[3, j + 1]
            ξq[j] = 0.0 if outside[p] else -Φj / Φ0
        for i in range(10):
            t = 0.0
            for k in range(4):
                t += dg[k] * J[k, i + 1]
            grad[p, i] = t
            for j in range(10):
                hess[p, i, j] = (H[i + 1, j + 1] + H[i + 1, 0] * ξq[j] + ξq[i] * H[0, j + 1]
                                 + H[0, 0] * ξq[i] * ξq[j])
        base = 2 + 4 * s
        cols[p, 0], cols[p, 1] = 0, 1
        cols[p, 2], cols[p, 3], cols[p, 4], cols[p, 5] = base, base + 1, base + 4, base + 5
        cols[p, 6], cols[p, 7], cols[p, 8], cols[p, 9] = base + 2, base + 3, base + 6, base + 7
        sliding[p] = xas + ls * ξ - x_node[p]
        xi_out[p] = ξ
        seg_out[p] = s
    return gap, grad, hess, cols, sliding, xi_out, seg_out, outside


@njit
def penalty_blocks(gap, grad, hess, area, penalty, smoothing, shift):  # pragma: no cover
    """Force −p A ∂g (m, n), tangent −A p'(g) ∂g ∂gᵀ − p A ∂²g (m, n, n) and pressure p (m,).

    ``sandwich.beam.contact_law.penalty_blocks`` in one loop over pairs, with the shifted
    softplus of ``sandwich.beam.contact_law.pressure_law`` (``shift`` = its c; ``smoothing`` 0:
    the plain penalty ε ⟨−g⟩) evaluated per pair: no (m,)-sized temporaries, no (m, n, n) products.
    """
    m, n = grad.shape
    f = np.empty((m, n))
    K = np.empty((m, n, n))
    p_out = np.empty(m)
    sp0 = np.log1p(np.exp(-shift))  # sp(−c) = ln(1 + e⁻ᶜ), as _softplus(−c)
    for i in range(m):
        g = gap[i]
        p = 0.0
        dp = 0.0
        if g < 0:
            if smoothing == 0:
                p = -penalty * g
                dp = -penalty
            else:
                x = -g / smoothing - shift
                sp = max(x, 0.0) + np.log1p(np.exp(-abs(x)))
                p = penalty * smoothing * (sp - sp0)
                dp = -penalty * 0.5 * (1.0 + np.tanh(0.5 * x))
        p_out[i] = p
        pa = p * area[i]
        da = -dp * area[i]
        for a in range(n):
            f[i, a] = -pa * grad[i, a]
            ga = da * grad[i, a]
            for b in range(n):
                K[i, a, b] = ga * grad[i, b] - pa * hess[i, a, b]
    return f, K, p_out

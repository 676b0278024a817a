"""Sum factorisation of a layer's force and tangent: the x–z tensor-product structure.

Every column of a layer's rows (:mod:`beam_element.layer_operators`) is one product of an
x-function and a z-function: the paper's DOFs X_kind(η) · Z_kind(ξ) (eq. 13, the DOF table of
:mod:`beam_element.dofs`), the core enrichment X_kind(η) · φ_k(ξ)
(:mod:`beam_element.core_basis`), h/2 folded into z-slopes and l/2 scaled on x-slopes outside.
With a tensor Gauss rule (η_p, ξ_q), a DOF a = (i, j) of x-function X_i and z-function Z_j has

    N,η_a(p, q) = X'_i(η_p) Z_j(ξ_q),   N,ξ_a(p, q) = X_i(η_p) Z'_j(ξ_q)   (likewise M)

and the tangent K_ab = Σ_pq Σ_kl H_kl(p, q) R_ka R_lb (eqs. 24-25, H the 4×4 point matrix of
:mod:`beam_element.kernels`) is summed in two stages, ξ first:

    T^t_{j j'}(p) = Σ_q H_t(p, q) A^t_j(ξ_q) B^t_{j'}(ξ_q)            (per element and η point)
    K_{(i j),(i' j')} = Σ_p Σ_t P^t_{i i'}(η_p) T^t_{j j'}(p)

with the four terms t of each field pair: for uu (k, l ∈ N,η N,ξ) t = 00, 11, 01, 10 with
(A, B) = (Z, Z), (Z', Z'), (Z, Z'), (Z', Z) and P = X'X', XX, X'X, XX' (H00, H11, H01, H01);
ww likewise with H22, H33, H23; uw (k ∈ N, l ∈ M) t = 02, 03, 12, 13, (A, B) = (Zu, Zw),
(Zu, Zw'), (Zu', Zw), (Zu', Zw'), P = X'X', X'X, XX', XX. The gradients and the force factor
the same way (ξ-contraction against Z, Z', then η-contraction against X, X'). The same points,
weights and point matrices as the packed kernel: only the order of the summation changes.

The DOF set need not be a full tensor product (the paper's core has no (H̄, H̄_t) DOF): each
DOF is one (i, j) of the grid of its field's x- and z-functions, the grid's other entries are
simply not read (their gradient contribution is zero). Per element the work is
G·Σ_t n_z² (first stage, GEMMs of (n_η·E) × n_ξ by n_ξ × n_z²) plus n_η·Σ_t n_x² n_z² (second
stage, GEMM of n_x² × 4 n_η by 4 n_η × E n_z²), against G·Σ_t n² for the packed kernel. Pairs of
z-functions whose supports are disjoint (sublayer hats) are left out of both stages.

A layer's factors are found from the DOF table (x-function of each column) and read off its
rows by least squares (z-function), then **checked**: every column of N, N,η, N,ξ, M, M,η, M,ξ
must equal the product to round-off, else :func:`factored_operators` returns None and the
layer keeps the packed kernel (e.g. a non-tensor rule, or the synthetic layers of the tests).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from beam_element.core_basis import mode_dofs
from beam_element.dofs import DOF_TABLE, ELEMENT_DOFS, NODE_DOFS
from beam_element.layer_operators import LayerOperators
from beam_element.shape_functions import x_shape
from sandwich.solver.jit import njit

__all__ = ["FactoredOperators", "factored_flops", "factored_operators"]

FACTOR_TOLERANCE = 1e-13  # relative: rows reproduced by the products to round-off
CHUNK = 32  # elements per block: the block's stage-1 outputs (≈ 4 n_η n_z² × 3 per element) in L2


@dataclass(frozen=True)
class FactoredOperators:
    """A layer's rows as x- and z-functions at a tensor rule (computed once per layer).

    Per field f (u, w): ``X``/``Xd`` (n_η, n_x) the x-functions and η-derivatives at the η
    points, ``Z``/``Zd`` (n_ξ, n_z) the z-functions and ξ-derivatives at the ξ points, ``ix``,
    ``jz`` (n_f,) the x- and z-function of each of the field's columns. Per field pair
    b (uu, ww, uw): ``Q`` (4, n_ξ, n_zp) the products A^t_j B^t_{j'} on the pair's z-pairs,
    ``P`` (n_xp, 4 n_η) the products P^t_{ii'} (columns t slowest), ``E`` (entries, 4) the
    layer columns (a, b), x-pair and z-pair of every entry of the pair's block that is not
    identically zero (uu, ww: a ≤ b only, z-pairs j ≤ j').
    """

    n_eta: int
    n_xi: int
    Xu: np.ndarray
    Xdu: np.ndarray
    Zu: np.ndarray
    Zdu: np.ndarray
    iu: np.ndarray
    ju: np.ndarray
    Xw: np.ndarray
    Xdw: np.ndarray
    Zw: np.ndarray
    Zdw: np.ndarray
    iw: np.ndarray
    jw: np.ndarray
    Quu: np.ndarray
    Puu: np.ndarray
    Euu: np.ndarray
    Qww: np.ndarray
    Pww: np.ndarray
    Eww: np.ndarray
    Quw: np.ndarray
    Puw: np.ndarray
    Euw: np.ndarray


def _tensor_grid(op: LayerOperators) -> tuple[np.ndarray, np.ndarray] | None:
    """η and ξ points of a tensor rule with η slowest, or None."""
    G = op.eta.size
    n_xi = int(np.argmax(op.eta != op.eta[0])) if np.any(op.eta != op.eta[0]) else G
    if n_xi == 0 or G % n_xi:
        return None
    e1, x1 = op.eta[::n_xi], op.xi[:n_xi]
    if not (np.array_equal(op.eta, np.repeat(e1, n_xi))
            and np.array_equal(op.xi, np.tile(x1, G // n_xi))):
        return None
    return e1, x1


def _x_function(op: LayerOperators, d: int) -> tuple[tuple[str, int], tuple] | None:
    """(x kind, node) and a key of the z-function of element DOF ``d``, from the DOF tables."""
    if d < ELEMENT_DOFS:
        node, i = divmod(d, NODE_DOFS)
        return (DOF_TABLE[i].x_kind, node), ("paper", DOF_TABLE[i].z_kind)
    if op.basis is None or op.level < 2:
        return None
    modes = mode_dofs(op.basis, op.level)
    node, j = divmod(d - ELEMENT_DOFS, len(modes))
    return (modes[j].x_kind, node), ("mode", modes[j].function)


def _field(op, cols, e1, x1, V, De, Dx):
    """x- and z-functions of one field's columns, or None if a column is not their product."""
    xkeys, zkeys, ix, jz = [], [], [], []
    for a in cols:
        found = _x_function(op, int(op.dofs[a]))
        if found is None:
            return None
        xk, zk = found
        if xk not in xkeys:
            xkeys.append(xk)
        if zk not in zkeys:
            zkeys.append(zk)
        ix.append(xkeys.index(xk))
        jz.append(zkeys.index(zk))
    X = np.stack([x_shape(k, node, e1)[0] for k, node in xkeys], axis=1)
    Xd = np.stack([x_shape(k, node, e1)[1] for k, node in xkeys], axis=1)
    n_eta, n_xi = e1.size, x1.size
    Z, Zd = np.zeros((n_xi, len(zkeys))), np.zeros((n_xi, len(zkeys)))
    for j in range(len(zkeys)):
        a = cols[jz.index(j)]  # the first column with this z-function: least squares in η
        x = X[:, ix[jz.index(j)]]
        Z[:, j] = x @ V[:, a].reshape(n_eta, n_xi) / (x @ x)
        Zd[:, j] = x @ Dx[:, a].reshape(n_eta, n_xi) / (x @ x)
    scale = max(np.abs(R[:, cols]).max() if cols.size else 0.0 for R in (V, De, Dx))
    for c, a in enumerate(cols):
        i, j = ix[c], jz[c]
        for R, x, z in ((V, X, Z), (De, Xd, Z), (Dx, X, Zd)):
            if np.abs(R[:, a] - np.outer(x[:, i], z[:, j]).ravel()).max() > \
                    FACTOR_TOLERANCE * scale:
                return None
    return X, Xd, Z, Zd, np.array(ix, dtype=np.int64), np.array(jz, dtype=np.int64)


def _pair_block(Xa, Xda, Za, Zda, ia, ja, Xb, Xdb, Zb, Zdb, ib, jb, cols_a, cols_b, symmetric):
    """Q, P and the entry list of one field pair (see :class:`FactoredOperators`).

    uu and ww (``symmetric``): K_{(i j),(i' j')} = K_{(i' j'),(i j)}, so only z-pairs j ≤ j'
    are formed (with every ordered x-pair): an entry with j > j' is read as its mirror.
    """
    if symmetric:  # t = 00, 11, 01, 10
        zt = ((Za, Za), (Zda, Zda), (Za, Zda), (Zda, Za))
        xt = ((Xda, Xda), (Xa, Xa), (Xda, Xa), (Xa, Xda))
        za, zb = np.triu_indices(Za.shape[1])
    else:  # t = 02, 03, 12, 13
        zt = ((Za, Zb), (Za, Zdb), (Zda, Zb), (Zda, Zdb))
        xt = ((Xda, Xdb), (Xda, Xb), (Xa, Xdb), (Xa, Xb))
        za, zb = (g.ravel() for g in np.meshgrid(np.arange(Za.shape[1]), np.arange(Zb.shape[1]),
                                                 indexing="ij"))
    full = np.stack([A[:, za] * B[:, zb] for A, B in zt])  # (4, n_ξ, z-pairs)
    keep = np.flatnonzero(np.any(full != 0, axis=(0, 1)))  # z-pairs with overlapping supports
    zindex = np.full((Za.shape[1], Zb.shape[1]), -1, dtype=np.int64)
    zindex[za[keep], zb[keep]] = np.arange(keep.size)
    Q = np.ascontiguousarray(full[:, :, keep])
    xa, xb = (g.ravel() for g in np.meshgrid(np.arange(Xa.shape[1]), np.arange(Xb.shape[1]),
                                             indexing="ij"))
    P = np.ascontiguousarray(np.concatenate([A[:, xa] * B[:, xb] for A, B in xt]).T)
    xindex = np.arange(xa.size).reshape(Xa.shape[1], Xb.shape[1])
    entries = []  # (a, b, x-pair, z-pair) of every entry not identically zero
    for a in range(ia.size):
        for b in range(a if symmetric else 0, ib.size):
            i, ip, j, jp = ia[a], ib[b], ja[a], jb[b]
            if symmetric and j > jp:  # K_ab = K_ba, formed for j ≤ j'
                i, ip, j, jp = ip, i, jp, j
            if zindex[j, jp] >= 0:
                entries.append((cols_a[a], cols_b[b], xindex[i, ip], zindex[j, jp]))
    return Q, P, np.array(entries, dtype=np.int64).reshape(-1, 4)


def factored_operators(op: LayerOperators) -> FactoredOperators | None:
    """The layer's x- and z-functions, or None where the rows do not factor (cached on ``op``)."""
    if "_factored_operators" in op.__dict__:
        return op.__dict__["_factored_operators"]
    out = None
    grid = None if op.membrane_average else _tensor_grid(op)
    if grid is not None:
        e1, x1 = grid
        u = np.asarray(op.u_columns, dtype=bool)
        fu = _field(op, np.flatnonzero(u), e1, x1, op.N, op.N_eta, op.N_xi)
        fw = _field(op, np.flatnonzero(~u), e1, x1, op.M, op.M_eta, op.M_xi)
        if fu is not None and fw is not None and fu[4].size and fw[4].size:
            cu, cw = np.flatnonzero(u), np.flatnonzero(~u)
            uu = _pair_block(*fu, *fu, cu, cu, True)
            ww = _pair_block(*fw, *fw, cw, cw, True)
            uw = _pair_block(*fu, *fw, cu, cw, False)
            c = np.ascontiguousarray
            out = FactoredOperators(
                n_eta=e1.size, n_xi=x1.size,
                Xu=c(fu[0]), Xdu=c(fu[1]), Zu=c(fu[2]), Zdu=c(fu[3]), iu=fu[4], ju=fu[5],
                Xw=c(fw[0]), Xdw=c(fw[1]), Zw=c(fw[2]), Zdw=c(fw[3]), iw=fw[4], jw=fw[5],
                Quu=uu[0], Puu=uu[1], Euu=uu[2], Qww=ww[0], Pww=ww[1], Eww=ww[2],
                Quw=uw[0], Puw=uw[1], Euw=uw[2])
    object.__setattr__(op, "_factored_operators", out)
    return out


def factored_flops(fo: FactoredOperators, tangent: bool = True) -> int:
    """Floating-point operations per element of the factored kernel's contractions.

    Gradients and force: per field and derivative, n_x n_z n_ξ + n_η n_ξ n_x multiply-adds.
    Tangent: the first stage's 12 GEMM columns per point (4 per pair, on the kept z-pairs) and
    the second stage, 4 n_η per (x-pair, z-pair) entry. Strains, stresses and H (O(1) per
    point) and the scatter are left out, as in :func:`beam_element.kernels.point_flops`.
    """
    G = fo.n_eta * fo.n_xi
    f = 0
    for X, Z in ((fo.Xu, fo.Zu), (fo.Xw, fo.Zw)):
        nx, nz = X.shape[1], Z.shape[1]
        f += 2 * 2 * 2 * (nx * nz * fo.n_xi + G * nx)  # gradients and force, 2 derivatives
    if not tangent:
        return f
    for Q, P in ((fo.Quu, fo.Puu), (fo.Qww, fo.Pww), (fo.Quw, fo.Puw)):
        nzp = Q.shape[2]
        f += 2 * 4 * G * nzp + 2 * P.shape[0] * P.shape[1] * nzp
    return f


@njit
def factored_kernel(u_l, lengths, width, Xu, Xdu, Zu, Zdu, iu, ju, Xw, Xdw, Zw, Zdw, iw, jw,
                    Quu, Puu, Euu, Qww, Pww, Eww, Quw, Puw, Euw, ucols, wcols, x_slope, weight, C, thickness, f_out, want_k, K_out, slots,
                    signs, data):  # pragma: no cover - compiled
    """Force into ``f_out`` (E, n); tangent into ``K_out`` (E, n, n) or ``data[slots]``.

    The same arguments and outputs as :func:`beam_element.kernels._kernel`, with the rows given
    by their factors (:class:`FactoredOperators`).
    """
    E = u_l.shape[0]
    Gx = Xu.shape[0]
    Gz = Zu.shape[0]
    nxu = Xu.shape[1]
    nzu = Zu.shape[1]
    nxw = Xw.shape[1]
    nzw = Zw.shape[1]
    nu = ucols.size
    nw = wcols.size
    n = x_slope.size
    blocks = K_out.shape[0] > 0
    scatter = slots.shape[0] > 0
    dz = 2.0 / thickness
    c00, c01, c02 = C[0, 0], C[0, 1], C[0, 2]
    c10, c11, c12 = C[1, 0], C[1, 1], C[1, 2]
    c20, c21, c22 = C[2, 0], C[2, 1], C[2, 2]
    nzp_uu = Quu.shape[2]
    nzp_ww = Qww.shape[2]
    nzp_uw = Quw.shape[2]
    # work arrays, one element at a time (gradients, force) and one block (the tangent)
    Ut = np.empty((nxu, nzu))
    Wt = np.empty((nxw, nzw))
    Vu0 = np.empty((nxu, Gz))
    Vu1 = np.empty((nxu, Gz))
    Vw0 = np.empty((nxw, Gz))
    Vw1 = np.empty((nxw, Gz))
    Cu0 = np.empty((Gx, Gz))
    Cu1 = np.empty((Gx, Gz))
    Cw0 = np.empty((Gx, Gz))
    Cw1 = np.empty((Gx, Gz))
    Au0 = np.empty((nxu, Gz))
    Au1 = np.empty((nxu, Gz))
    Aw0 = np.empty((nxw, Gz))
    Aw1 = np.empty((nxw, Gz))
    scale = np.empty(n)
    Ke = np.zeros((n, n))  # entries identically zero stay zero
    ch = min(CHUNK, E) if want_k else 1
    Hb = np.empty((10, Gx * ch, Gz))  # H00 H11 H01 | H22 H33 H23 | H02 H03 H12 H13, (p, e, q)
    Suu = np.empty((4, Gx * ch, nzp_uu))
    Sww = np.empty((4, Gx * ch, nzp_ww))
    Suw = np.empty((4, Gx * ch, nzp_uw))
    huu = (0, 1, 2, 2)
    hww = (3, 4, 5, 5)
    huw = (6, 7, 8, 9)
    for e0 in range(0, E, CHUNK):
        ec = min(CHUNK, E - e0)
        for i in range(ec):
            e = e0 + i
            half = 0.5 * lengths[e]
            for a in range(n):  # u_ref = scale ⊙ u_e: l/2 on x-slope DOFs
                scale[a] = half if x_slope[a] else 1.0
            Ut[:] = 0.0
            Wt[:] = 0.0
            for a in range(nu):
                Ut[iu[a], ju[a]] = u_l[e, ucols[a]] * scale[ucols[a]]
            for a in range(nw):
                Wt[iw[a], jw[a]] = u_l[e, wcols[a]] * scale[wcols[a]]
            # ξ first: V[i, q] = Σ_j Ũ[i, j] Z_j(ξ_q), then η: D[p, q] = Σ_i X_i(η_p) V[i, q]
            for r in range(nxu):
                for q in range(Gz):
                    s0 = 0.0
                    s1 = 0.0
                    for j in range(nzu):
                        s0 += Ut[r, j] * Zu[q, j]
                        s1 += Ut[r, j] * Zdu[q, j]
                    Vu0[r, q] = s0
                    Vu1[r, q] = s1
            for r in range(nxw):
                for q in range(Gz):
                    s0 = 0.0
                    s1 = 0.0
                    for j in range(nzw):
                        s0 += Wt[r, j] * Zw[q, j]
                        s1 += Wt[r, j] * Zdw[q, j]
                    Vw0[r, q] = s0
                    Vw1[r, q] = s1
            dx = 2.0 / lengths[e]
            dV0 = width * (0.5 * lengths[e]) * (0.5 * thickness)  # b l h / 4, eq. (19)
            for p in range(Gx):
                for q in range(Gz):
                    du0 = 0.0
                    du1 = 0.0
                    for r in range(nxu):
                        du0 += Xdu[p, r] * Vu0[r, q]
                        du1 += Xu[p, r] * Vu1[r, q]
                    dw0 = 0.0
                    dw1 = 0.0
                    for r in range(nxw):
                        dw0 += Xdw[p, r] * Vw0[r, q]
                        dw1 += Xw[p, r] * Vw1[r, q]
                    ux = dx * du0  # eq. (15)
                    uz = dz * du1
                    wx = dx * dw0
                    wz = dz * dw1
                    ex = ux + 0.5 * (ux * ux + wx * wx)  # Green-Lagrange, eq. (15)
                    ez = wz + 0.5 * (uz * uz + wz * wz)
                    gm = uz + wx + ux * uz + wx * wz
                    dV = dV0 * weight[p * Gz + q]
                    sa = dV * (c00 * ex + c01 * ez + c02 * gm)  # dV σ, eq. (3)
                    sb = dV * (c10 * ex + c11 * ez + c12 * gm)
                    st = dV * (c20 * ex + c21 * ez + c22 * gm)
                    # eq. (19): Σ_g dV σ·B = Σ_g c·R, the rows of eq. (17) sorted by R
                    Cu0[p, q] = dx * (sa * (1 + ux) + st * uz)
                    Cu1[p, q] = dz * (sb * uz + st * (1 + ux))
                    Cw0[p, q] = dx * (sa * wx + st * (1 + wz))
                    Cw1[p, q] = dz * (sb * (1 + wz) + st * wx)
                    if not want_k:
                        continue
                    p00 = dx * (1 + ux)  # Φ of strain_coefficients (B = Φ R, eq. 17)
                    p02 = dx * wx
                    p11 = dz * uz
                    p13 = dz * (1 + wz)
                    p20 = dx * uz
                    p21 = dz * (1 + ux)
                    p22 = dx * (1 + wz)
                    p23 = dz * wx
                    a00 = c00 * p00 + c02 * p20  # CΦ
                    a01 = c01 * p11 + c02 * p21
                    a02 = c00 * p02 + c02 * p22
                    a03 = c01 * p13 + c02 * p23
                    a11 = c11 * p11 + c12 * p21
                    a12 = c10 * p02 + c12 * p22
                    a13 = c11 * p13 + c12 * p23
                    a20 = c20 * p00 + c22 * p20
                    a21 = c21 * p11 + c22 * p21
                    a22 = c20 * p02 + c22 * p22
                    a23 = c21 * p13 + c22 * p23
                    sx = sa * dx * dx  # eq. (25)
                    sz = sb * dz * dz
                    sxz = st * dx * dz
                    row = p * ec + i  # H = dV Φᵀ C Φ (eq. 24) + the stress terms (eq. 25)
                    Hb[0, row, q] = dV * (p00 * a00 + p20 * a20) + sx  # H00
                    Hb[1, row, q] = dV * (p11 * a11 + p21 * a21) + sz  # H11
                    Hb[2, row, q] = dV * (p00 * a01 + p20 * a21) + sxz  # H01
                    Hb[3, row, q] = dV * (p02 * a02 + p22 * a22) + sx  # H22
                    Hb[4, row, q] = dV * (p13 * a13 + p23 * a23) + sz  # H33
                    Hb[5, row, q] = dV * (p02 * a03 + p22 * a23) + sxz  # H23
                    Hb[6, row, q] = dV * (p00 * a02 + p20 * a22)  # H02
                    Hb[7, row, q] = dV * (p00 * a03 + p20 * a23)  # H03
                    Hb[8, row, q] = dV * (p11 * a12 + p21 * a22)  # H12
                    Hb[9, row, q] = dV * (p11 * a13 + p21 * a23)  # H13
            # force: A[i, q] = Σ_p X_i(η_p) c(p, q), then F[i, j] = Σ_q A[i, q] Z_j(ξ_q)
            for r in range(nxu):
                for q in range(Gz):
                    s0 = 0.0
                    s1 = 0.0
                    for p in range(Gx):
                        s0 += Xdu[p, r] * Cu0[p, q]
                        s1 += Xu[p, r] * Cu1[p, q]
                    Au0[r, q] = s0
                    Au1[r, q] = s1
            for r in range(nxw):
                for q in range(Gz):
                    s0 = 0.0
                    s1 = 0.0
                    for p in range(Gx):
                        s0 += Xdw[p, r] * Cw0[p, q]
                        s1 += Xw[p, r] * Cw1[p, q]
                    Aw0[r, q] = s0
                    Aw1[r, q] = s1
            for a in range(nu):
                r = iu[a]
                j = ju[a]
                s = 0.0
                for q in range(Gz):
                    s += Au0[r, q] * Zu[q, j] + Au1[r, q] * Zdu[q, j]
                f_out[e, ucols[a]] = s * scale[ucols[a]]
            for a in range(nw):
                r = iw[a]
                j = jw[a]
                s = 0.0
                for q in range(Gz):
                    s += Aw0[r, q] * Zw[q, j] + Aw1[r, q] * Zdw[q, j]
                f_out[e, wcols[a]] = s * scale[wcols[a]]
        if not want_k:
            continue
        m = Gx * ec
        # stage 1 (ξ): S_t[(p, e), zpair] = Σ_q H_t[(p, e), q] Q_t[q, zpair]
        for t in range(4):
            np.dot(Hb[huu[t], :m], Quu[t], Suu[t, :m])
            np.dot(Hb[hww[t], :m], Qww[t], Sww[t, :m])
            np.dot(Hb[huw[t], :m], Quw[t], Suw[t, :m])
        # stage 2 (η): K[xpair, (e, zpair)] = Σ_(t, p) P[xpair, (t, p)] S[(t, p), (e, zpair)]
        if ec == ch:
            Kuu = np.dot(Puu, Suu.reshape(4 * Gx, ec * nzp_uu))
            Kww = np.dot(Pww, Sww.reshape(4 * Gx, ec * nzp_ww))
            Kuw = np.dot(Puw, Suw.reshape(4 * Gx, ec * nzp_uw))
        else:  # the last, partial block: its rows are the first m of each S_t
            Kuu = np.dot(Puu, np.ascontiguousarray(Suu[:, :m]).reshape(4 * Gx, ec * nzp_uu))
            Kww = np.dot(Pww, np.ascontiguousarray(Sww[:, :m]).reshape(4 * Gx, ec * nzp_ww))
            Kuw = np.dot(Puw, np.ascontiguousarray(Suw[:, :m]).reshape(4 * Gx, ec * nzp_uw))
        for i in range(ec):
            e = e0 + i
            half = 0.5 * lengths[e]
            for a in range(n):
                scale[a] = half if x_slope[a] else 1.0
            for K, En, nzp in ((Kuu, Euu, nzp_uu), (Kww, Eww, nzp_ww), (Kuw, Euw, nzp_uw)):
                for t in range(En.shape[0]):
                    ia = En[t, 0]
                    ib = En[t, 1]
                    v = K[En[t, 2], i * nzp + En[t, 3]] * scale[ia] * scale[ib]
                    Ke[ia, ib] = v
                    Ke[ib, ia] = v
            if blocks:
                K_out[e] = Ke
            if scatter:  # row by row: slots and data in memory order
                for a in range(n):
                    for b in range(n):
                        s = slots[e, a, b]
                        if s >= 0:
                            data[s] += signs[e, a, b] * Ke[a, b]

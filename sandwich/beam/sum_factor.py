"""Sum factorisation of a layer's force and tangent: the x–z tensor-product structure.

Every column of a layer's rows (:mod:`sandwich.beam.layer_operators`) is one product of an
x-function and a z-function: the paper's DOFs X_kind(η) · Z_kind(ξ) (eq. 13, the DOF table of
:mod:`sandwich.beam.dofs`), the core enrichment X_kind(η) · φ_k(ξ)
(:mod:`sandwich.beam.core_basis`), h/2 folded into z-slopes and l/2 scaled on x-slopes outside.
With a tensor Gauss rule (η_p, ξ_q), a DOF a = (i, j) of x-function X_i and z-function Z_j has

    N,η_a(p, q) = X'_i(η_p) Z_j(ξ_q),   N,ξ_a(p, q) = X_i(η_p) Z'_j(ξ_q)   (likewise M)

and the tangent K_ab = Σ_pq Σ_kl H_kl(p, q) R_ka R_lb (eqs. 24-25, H the 4×4 point matrix of
:mod:`sandwich.beam.kernels`) is summed in two stages, ξ first:

    T^t_{j j'}(p) = Σ_q H_t(p, q) A^t_j(ξ_q) B^t_{j'}(ξ_q)            (per element and η point)
    K_{(i j),(i' j')} = Σ_p Σ_t P^t_{i i'}(η_p) T^t_{j j'}(p)

with the four terms t of each field pair: for uu (k, l ∈ N,η N,ξ) t = 00, 11, 01, 10 with
(A, B) = (Z, Z), (Z', Z'), (Z, Z'), (Z', Z) and P = X'X', XX, X'X, XX' (H00, H11, H01, H01);
ww likewise with H22, H33, H23; uw (k ∈ N, l ∈ M) t = 02, 03, 12, 13, (A, B) = (Zu, Zw),
(Zu, Zw'), (Zu', Zw), (Zu', Zw'), P = X'X', X'X, XX', XX. The gradients and the force factor
the same way (ξ-contraction against Z, Z', then η-contraction against X, X'). The same points,
weights and point matrices as the packed kernel: only the order of the summation changes. The
gradients' and the force's contractions run over a block of elements at once, as GEMMs with
the element index inside ((function, element) rows, (element, point) columns): per element they
were loops of n_ξ over a handful of functions, bound by loop overhead (level 2, 240 elements:
the force 0.96 → 0.44 ms, force + tangent 3.45 → 3.02 ms; level 3: the force 1.00 → 0.73 ms,
force + tangent 7.5 → 7.1-7.4 ms, within the spread between processes; docs/speed.md).

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

from sandwich.beam.core_basis import mode_dofs
from sandwich.beam.dofs import DOF_TABLE, ELEMENT_DOFS, NODE_DOFS
from sandwich.beam.layer_operators import LayerOperators
from sandwich.beam.shape_functions import x_shape
from sandwich.solver.jit import njit

__all__ = ["FactoredOperators", "factored_flops", "factored_operators"]

FACTOR_TOLERANCE = 1e-13  # relative: rows reproduced by the products to round-off
CHUNK = 16  # elements per block (measured: 8-16 best at levels 2-4; 32 +5 %, 64 +25 %)


@dataclass(frozen=True)
class FactoredOperators:
    """A layer's rows as x- and z-functions at a tensor rule (computed once per layer).

    Per field f (u, w): ``X``/``Xd`` (n_η, n_x) the x-functions and η-derivatives at the η
    points, ``ZT``/``ZdT`` (n_z, n_ξ) the z-functions and ξ-derivatives at the ξ points, ``ix``,
    ``jz`` (n_f,) the x- and z-function of each of the field's columns. Per field pair
    b (uu, ww, uw): ``Q`` (4, n_ξ, n_zp) the products A^t_j B^t_{j'} on the pair's z-pairs,
    ``P`` (n_xp, 4 n_η) the products P^t_{ii'} (columns t slowest, every ordered x-pair);
    ``entries`` (3, n, n): block (0 uu, 1 ww, 2 uw, −1 identically zero), x-pair and z-pair of
    each entry (a, b) of the layer's block (uu, ww: formed for z-pairs j ≤ j', the others
    read as their mirror).
    """

    n_eta: int
    n_xi: int
    Xu: np.ndarray
    Xdu: np.ndarray
    ZuT: np.ndarray
    ZduT: np.ndarray
    iu: np.ndarray
    ju: np.ndarray
    Xw: np.ndarray
    Xdw: np.ndarray
    ZwT: np.ndarray
    ZdwT: np.ndarray
    iw: np.ndarray
    jw: np.ndarray
    Quu: np.ndarray
    Puu: np.ndarray
    Qww: np.ndarray
    Pww: np.ndarray
    Quw: np.ndarray
    Puw: np.ndarray
    entries: np.ndarray


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
    xp = np.full((ia.size, ib.size), -1, dtype=np.int64)  # -1: identically zero
    zp = np.full((ia.size, ib.size), -1, dtype=np.int64)
    for a in range(ia.size):
        for b in range(ib.size):
            i, ip, j, jp = ia[a], ib[b], ja[a], jb[b]
            if symmetric and (j > jp or (j == jp and i > ip)):  # K_ab = K_ba, formed for
                i, ip, j, jp = ip, i, jp, j  # j ≤ j' (i ≤ i' if j = j'): exactly symmetric
            if zindex[j, jp] >= 0:
                xp[a, b], zp[a, b] = xindex[i, ip], zindex[j, jp]
    return Q, P, xp, zp


def _entry_map(n, cu, cw, uu, ww, uw):
    """(block, x-pair, z-pair) of every entry (a, b) of the layer's n × n block.

    Blocks 0 uu, 1 ww, 2 uw (a w, b u: the uw entry (b, a)), −1 identically zero.
    """
    m = np.full((3, n, n), -1, dtype=np.int64)
    for block, (rows, cols, xp, zp) in enumerate(((cu, cu, uu[2], uu[3]), (cw, cw, ww[2], ww[3]),
                                                   (cu, cw, uw[2], uw[3]))):
        live = zp >= 0
        r, c = np.meshgrid(rows, cols, indexing="ij")
        for R, Cc in ((r, c), (c, r)) if block == 2 else ((r, c),):
            m[0][R[live], Cc[live]] = block
            m[1][R[live], Cc[live]] = xp[live]
            m[2][R[live], Cc[live]] = zp[live]
    return m


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
                Xu=c(fu[0]), Xdu=c(fu[1]), ZuT=c(fu[2].T), ZduT=c(fu[3].T), iu=fu[4], ju=fu[5],
                Xw=c(fw[0]), Xdw=c(fw[1]), ZwT=c(fw[2].T), ZdwT=c(fw[3].T), iw=fw[4],
                jw=fw[5],
                Quu=uu[0], Puu=uu[1], Qww=ww[0], Pww=ww[1], Quw=uw[0], Puw=uw[1],
                entries=_entry_map(op.dofs.size, cu, cw, uu, ww, uw))
    object.__setattr__(op, "_factored_operators", out)
    return out


def factored_flops(fo: FactoredOperators, tangent: bool = True) -> int:
    """Floating-point operations per element of the factored kernel's contractions.

    Gradients and force: per field and derivative, n_x n_z n_ξ + n_η n_ξ n_x multiply-adds.
    Tangent: the first stage's 12 GEMM columns per point (4 per pair, on the kept z-pairs) and
    the second stage, 4 n_η per (x-pair, z-pair) entry. Strains, stresses and H (O(1) per
    point) and the scatter are left out, as in :func:`sandwich.beam.packed_kernel.point_flops`.
    """
    G = fo.n_eta * fo.n_xi
    f = 0
    for X, Z in ((fo.Xu, fo.ZuT), (fo.Xw, fo.ZwT)):
        nx, nz = X.shape[1], Z.shape[0]
        f += 2 * 2 * 2 * (nx * nz * fo.n_xi + G * nx)  # gradients and force, 2 derivatives
    if not tangent:
        return f
    for Q, P in ((fo.Quu, fo.Puu), (fo.Qww, fo.Pww), (fo.Quw, fo.Puw)):
        nzp = Q.shape[2]
        f += 2 * 4 * G * nzp + 2 * P.shape[0] * P.shape[1] * nzp
    return f


@njit(reassociate=True)
def factored_kernel(u_l, lengths, width, Xu, Xdu, ZuT, ZduT, iu, ju, Xw, Xdw, ZwT, ZdwT, iw, jw,
                    Quu, Puu, Qww, Pww, Quw, Puw, entries, ucols, wcols, x_slope, weight, C,
                    thickness, f_out, want_k, K_out, slots, signs,
                    data):  # pragma: no cover - compiled
    """Force into ``f_out`` (E, n); tangent into ``K_out`` (E, n, n) or ``data[slots]``.

    The same arguments and outputs as :func:`sandwich.beam.packed_kernel.packed_kernel`, with the
    rows given by their factors (:class:`FactoredOperators`; z-functions transposed, (n_z, n_ξ)).
    """
    E = u_l.shape[0]
    Gx = Xu.shape[0]
    Gz = ZuT.shape[1]
    nu = ucols.size
    nw = wcols.size
    n = x_slope.size
    blocks = K_out.shape[0] > 0
    scatter = slots.shape[0] > 0
    dz = 2.0 / thickness
    c00, c01, c02 = C[0, 0], C[0, 1], C[0, 2]
    c10, c11, c12 = C[1, 0], C[1, 1], C[1, 2]
    c20, c21, c22 = C[2, 0], C[2, 1], C[2, 2]
    nzp = (Quu.shape[2], Qww.shape[2], Quw.shape[2])
    nxp = (Puu.shape[0], Pww.shape[0], Puw.shape[0])
    # the ξ-functions transposed once (the force's last contraction)
    ZuN = np.ascontiguousarray(ZuT.T)
    ZduN = np.ascontiguousarray(ZduT.T)
    ZwN = np.ascontiguousarray(ZwT.T)
    ZdwN = np.ascontiguousarray(ZdwT.T)
    nxu, nzu, nxw, nzw = Xu.shape[1], ZuT.shape[0], Xw.shape[1], ZwT.shape[0]
    XuT = np.ascontiguousarray(Xu.T)
    XduT = np.ascontiguousarray(Xdu.T)
    XwT = np.ascontiguousarray(Xw.T)
    XdwT = np.ascontiguousarray(Xdw.T)
    cur = -1  # the element count the block arrays below are sized for
    scale = np.empty(n)
    ch = min(CHUNK, E) if want_k else 1
    Hb = np.zeros((10, Gx * ch, Gz))  # H00 H11 H01 | H22 H33 H23 | H02 H03 H12 H13, (p, e, q)
    Suu = np.empty((4, Gx * ch, nzp[0]))
    Sww = np.empty((4, Gx * ch, nzp[1]))
    Suw = np.empty((4, Gx * ch, nzp[2]))
    total = nxp[0] * ch * nzp[0] + nxp[1] * ch * nzp[1] + nxp[2] * ch * nzp[2]
    Kall = np.zeros(total + 1)  # the three pair blocks of a block of elements, then a zero
    src = np.empty((n, n), dtype=np.int64)  # entry (a, b) of element i: Kall[src + i step]
    step = np.empty((n, n), dtype=np.int64)
    src_ec = -1
    huu = (0, 1, 2, 2)
    hww = (3, 4, 5, 5)
    huw = (6, 7, 8, 9)
    for e0 in range(0, E, CHUNK):
        ec = min(CHUNK, E - e0)
        if ec != cur:  # block arrays, (function, element, point) with the element inside
            cur = ec
            Ub = np.empty((nxu * ec, nzu))
            Wb = np.empty((nxw * ec, nzw))
            Du0 = np.empty((Gx, ec * Gz))
            Du1 = np.empty((Gx, ec * Gz))
            Dw0 = np.empty((Gx, ec * Gz))
            Dw1 = np.empty((Gx, ec * Gz))
            Cu0 = np.empty((Gx, ec * Gz))
            Cu1 = np.empty((Gx, ec * Gz))
            Cw0 = np.empty((Gx, ec * Gz))
            Cw1 = np.empty((Gx, ec * Gz))
        # u_ref = scale ⊙ u_e (l/2 on x-slope DOFs) on the grid of x- and z-functions
        Ub[:] = 0.0
        Wb[:] = 0.0
        for i in range(ec):
            half = 0.5 * lengths[e0 + i]
            for a in range(nu):
                c = ucols[a]
                Ub[iu[a] * ec + i, ju[a]] = u_l[e0 + i, c] * (half if x_slope[c] else 1.0)
            for a in range(nw):
                c = wcols[a]
                Wb[iw[a] * ec + i, jw[a]] = u_l[e0 + i, c] * (half if x_slope[c] else 1.0)
        # ξ first: V[(i, e), q] = Σ_j Ũ[(i, e), j] Z_j(ξ_q), then η: D[p, (e, q)] = Σ_i X_i(η_p)
        # V[i, (e, q)] — one GEMM each for the block's elements
        np.dot(Xdu, np.dot(Ub, ZuT).reshape(nxu, ec * Gz), Du0)  # N,η u
        np.dot(Xu, np.dot(Ub, ZduT).reshape(nxu, ec * Gz), Du1)  # N,ξ u
        np.dot(Xdw, np.dot(Wb, ZwT).reshape(nxw, ec * Gz), Dw0)
        np.dot(Xw, np.dot(Wb, ZdwT).reshape(nxw, ec * Gz), Dw1)
        for i in range(ec):
            e = e0 + i
            dx = 2.0 / lengths[e]
            dV0 = width * (0.5 * lengths[e]) * (0.5 * thickness)  # b l h / 4, eq. (19)
            for p in range(Gx):
                row = p * ec + i  # rows of the block's point matrices: (p, e)
                for q in range(Gz):
                    ux = dx * Du0[p, i * Gz + q]  # eq. (15)
                    uz = dz * Du1[p, i * Gz + q]
                    wx = dx * Dw0[p, i * Gz + q]
                    wz = dz * Dw1[p, i * Gz + q]
                    ex = ux + 0.5 * (ux * ux + wx * wx)  # Green-Lagrange, eq. (15)
                    ez = wz + 0.5 * (uz * uz + wz * wz)
                    gm = uz + wx + ux * uz + wx * wz
                    dV = dV0 * weight[p * Gz + q]
                    sa = dV * (c00 * ex + c01 * ez + c02 * gm)  # dV σ, eq. (3)
                    sb = dV * (c10 * ex + c11 * ez + c12 * gm)
                    st = dV * (c20 * ex + c21 * ez + c22 * gm)
                    # eq. (19): Σ_g dV σ·B = Σ_g c·R, the rows of eq. (17) sorted by R
                    Cu0[p, i * Gz + q] = dx * (sa * (1 + ux) + st * uz)
                    Cu1[p, i * Gz + q] = dz * (sb * uz + st * (1 + ux))
                    Cw0[p, i * Gz + q] = dx * (sa * wx + st * (1 + wz))
                    Cw1[p, i * Gz + q] = dz * (sb * (1 + wz) + st * wx)
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
                    # H = dV Φᵀ C Φ (eq. 24) + the stress terms (eq. 25)
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
        # force: A[i, (e, q)] = Σ_p X_i(η_p) c(p, (e, q)), then
        # f_(i j)(e) = Σ_q A[(i, e), q] Z_j(ξ_q) + the ξ-derivative's twin — GEMMs again
        Fu = np.dot(np.dot(XduT, Cu0).reshape(nxu * ec, Gz), ZuN) + \
            np.dot(np.dot(XuT, Cu1).reshape(nxu * ec, Gz), ZduN)
        Fw = np.dot(np.dot(XdwT, Cw0).reshape(nxw * ec, Gz), ZwN) + \
            np.dot(np.dot(XwT, Cw1).reshape(nxw * ec, Gz), ZdwN)
        for i in range(ec):
            half = 0.5 * lengths[e0 + i]
            for a in range(nu):
                c = ucols[a]
                f_out[e0 + i, c] = Fu[iu[a] * ec + i, ju[a]] * (half if x_slope[c] else 1.0)
            for a in range(nw):
                c = wcols[a]
                f_out[e0 + i, c] = Fw[iw[a] * ec + i, jw[a]] * (half if x_slope[c] else 1.0)
        if not want_k:
            continue
        m = Gx * ec
        # stage 1 (ξ): S_t[(p, e), z-pair] = Σ_q H_t[(p, e), q] Q_t[q, z-pair]
        for t in range(4):
            np.dot(Hb[huu[t], :m], Quu[t], Suu[t, :m])
            np.dot(Hb[hww[t], :m], Qww[t], Sww[t, :m])
            np.dot(Hb[huw[t], :m], Quw[t], Suw[t, :m])
        # stage 2 (η): K[x-pair, (e, z-pair)] = Σ_(t, p) P[x-pair, (t, p)] S[(t, p), (e, z-pair)]
        o1 = nxp[0] * ec * nzp[0]
        o2 = o1 + nxp[1] * ec * nzp[1]
        o3 = o2 + nxp[2] * ec * nzp[2]
        for S, P, lo, hi, w in ((Suu, Puu, 0, o1, nzp[0]), (Sww, Pww, o1, o2, nzp[1]),
                                (Suw, Puw, o2, o3, nzp[2])):
            St = S.reshape(4 * Gx, ec * w) if ec == ch else \
                np.ascontiguousarray(S[:, :m]).reshape(4 * Gx, ec * w)
            np.dot(P, St, Kall[lo:hi].reshape(P.shape[0], ec * w))
        if src_ec != ec:  # where each entry (a, b) of element i sits in Kall
            src_ec = ec
            offsets = (0, o1, o2)
            for a in range(n):
                for b in range(n):
                    blk = entries[0, a, b]
                    if blk < 0:
                        src[a, b] = total  # the zero
                        step[a, b] = 0
                    else:
                        src[a, b] = offsets[blk] + entries[1, a, b] * ec * nzp[blk] + \
                            entries[2, a, b]
                        step[a, b] = nzp[blk]
        for i in range(ec):
            e = e0 + i
            half = 0.5 * lengths[e]
            for a in range(n):
                scale[a] = half if x_slope[a] else 1.0
            for a in range(n):  # row by row: slots and data in memory order
                for b in range(n):
                    v = Kall[src[a, b] + i * step[a, b]] * (scale[a] * scale[b])
                    if blocks:
                        K_out[e, a, b] = v
                    if scatter:
                        s = slots[e, a, b]
                        if s >= 0:
                            data[s] += signs[e, a, b] * v

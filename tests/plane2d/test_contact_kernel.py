"""The contact gap and its derivatives (pure NumPy)."""

import numpy as np
import pytest

from sandwich.plane2d import contact as ct

pytestmark = pytest.mark.dolfinx


def test_gap_gradient_and_hessian_match_finite_differences():
    rng = np.random.default_rng(1)
    for _ in range(5):
        X = rng.standard_normal(8)
        X[6:] += 3.0  # keep the chord away from zero length
        g, dg, H = ct.gap_with_derivatives(X[:2], X[2:4], X[4:6], X[6:])
        h = 1e-6
        E = np.eye(8)
        fd_g = np.array([(ct.gap_with_derivatives(*np.split(X + h * E[i], 4))[0]
                          - ct.gap_with_derivatives(*np.split(X - h * E[i], 4))[0]) / (2 * h)
                         for i in range(8)])
        fd_H = np.array([(ct.gap_with_derivatives(*np.split(X + h * E[i], 4))[1]
                          - ct.gap_with_derivatives(*np.split(X - h * E[i], 4))[1]) / (2 * h)
                         for i in range(8)])
        assert np.allclose(dg, fd_g, atol=1e-8)
        assert np.allclose(H, fd_H, atol=1e-7)
        assert np.allclose(H, H.T)


def test_gap_sign_and_value():
    # core lip along +x: normal +z; a point 0.3 above the anchor has gap +0.3
    g, _, _ = ct.gap_with_derivatives(np.array([1.0, 0.3]), np.array([1.0, 0.0]),
                                      np.array([0.0, 0.0]), np.array([2.0, 0.0]))
    assert g == pytest.approx(0.3)
    g, _, _ = ct.gap_with_derivatives(np.array([1.0, -0.2]), np.array([1.0, 0.0]),
                                      np.array([0.0, 0.0]), np.array([2.0, 0.0]))
    assert g == pytest.approx(-0.2)


def test_slave_weights_integrate_length():
    x = np.array([1.0, 2.0, 3.0, 4.0, 5.0])  # between tips 0 and 6: 3 quadratic facets
    w = ct.slave_weights(x, 0.0, 6.0)
    # Simpson weights: mid 2/3 h, shared corner 1/6 h + 1/6 h with h = 2
    assert np.allclose(w, [4 / 3, 2 / 3, 4 / 3, 2 / 3, 4 / 3])


def test_batched_gap_derivatives_equal_the_single_slave_ones():
    # reference: gap_with_derivatives, itself checked against central differences above
    rng = np.random.default_rng(7)
    X = rng.standard_normal((6, 8))
    X[:, 6:] += 3.0
    d = X[:, 0:2] - X[:, 2:4]
    a = X[:, 6:8] - X[:, 4:6]
    g, dg, H = ct.gaps_with_derivatives(d, a)
    for i in range(6):
        g1, dg1, H1 = ct.gap_with_derivatives(np.zeros(2) + d[i], np.zeros(2), X[i, 4:6], X[i, 6:8])
        assert g[i] == pytest.approx(g1, rel=1e-13, abs=1e-14)
        assert np.allclose(dg[i], dg1, rtol=1e-13, atol=1e-14)
        assert np.allclose(H[i], H1, rtol=1e-12, atol=1e-13)


def _chain(n_master=13, slaves=None):
    """A straight core lip along +x (master nodes at x = 0, 0.5, …) and face slaves on it."""
    x_master = np.column_stack([0.5 * np.arange(n_master), np.zeros(n_master)])
    xs = x_master[2:-2] if slaves is None else slaves
    ns = len(xs)
    x_ref = np.vstack([xs, x_master])
    anchor = np.arange(ns) + 2 if slaves is None else np.zeros(ns, dtype=np.int64) + 2
    return x_ref, ns, anchor


def _pair(ns, n_master, anchor, weight=0.7, k=50.0, b=2.0, x_ref=None):
    return ct.ContactPair(np.arange(ns), np.arange(n_master) + ns, anchor, np.full(ns, weight),
                          k, b, np.zeros(ns) if x_ref is None else x_ref)


def test_segment_parameter_derivatives_match_finite_differences():
    rng = np.random.default_rng(11)
    X = rng.standard_normal((4, 6))
    X[:, 4:] += 2.0

    def xi(Y):
        return ct.segment_parameter(Y[:, 0:2] - Y[:, 2:4], Y[:, 4:6] - Y[:, 2:4])

    v, dv, H = xi(X)
    h = 1e-6
    for i in range(6):
        E = np.zeros_like(X)
        E[:, i] = h
        fd = (xi(X + E)[0] - xi(X - E)[0]) / (2 * h)
        fd2 = (xi(X + E)[1] - xi(X - E)[1]) / (2 * h)
        assert np.allclose(dv[:, i], fd, atol=1e-8)
        assert np.allclose(H[:, :, i], fd2, atol=1e-7)


def _blended(X):
    """blended_gaps at the five positions (s, p, a, b, q) stacked as X (n, 10)."""
    s, p, a, b, q = (X[:, 2 * i: 2 * i + 2] for i in range(5))
    return ct.blended_gaps(s - a, b - p, s - b, q - a, s - a, b - a)


def test_blended_gap_derivatives_match_finite_differences():
    # reference: central differences of g and of its gradient, slaves inside their segment
    rng = np.random.default_rng(5)
    n = 6
    base = np.array([-1.0, 0.0, 0.0, 0.0, 1.0, 0.1, 2.0, 0.3])  # p, a, b, q on a curved lip
    X = np.zeros((n, 10))
    X[:, 2:] = base + 0.05 * rng.standard_normal((n, 8))
    X[:, 0] = rng.uniform(0.15, 0.85, n)  # ξ well inside (0, 1)
    X[:, 1] = 0.02 * rng.standard_normal(n)
    g, xi, dg, H = _blended(X)
    assert np.all((xi > 0.05) & (xi < 0.95))
    h = 1e-6
    for i in range(10):
        E = np.zeros_like(X)
        E[:, i] = h
        assert np.allclose(dg[:, i], (_blended(X + E)[0] - _blended(X - E)[0]) / (2 * h),
                           atol=1e-8)
        assert np.allclose(H[:, :, i], (_blended(X + E)[2] - _blended(X - E)[2]) / (2 * h),
                           atol=1e-6)
    assert np.allclose(H, H.transpose(0, 2, 1))


def test_blended_gap_is_exact_on_a_straight_lip_and_close_on_a_curved_one():
    # reference: the distance to the line, and to the circle the master nodes lie on (closed form)
    X = np.zeros((3, 10))
    X[:, 2:] = [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 2.0, 0.0]
    X[:, 0] = [0.1, 0.5, 0.9]
    X[:, 1] = [-0.01, 0.003, 0.2]
    assert np.allclose(_blended(X)[0], X[:, 1], rtol=1e-14, atol=1e-15)
    R, spacing = 40.0, 0.5  # a lip of curvature 1/R with master nodes 0.5 mm apart
    angles = spacing / R * np.array([-1.0, 0.0, 1.0, 2.0])
    nodes = np.column_stack([R * np.sin(angles), R * np.cos(angles) - R])  # convex, normal +z
    t = np.linspace(0.02, 0.98, 7)
    theta = spacing / R * t
    depth = np.array([-2e-3, 0.0, 1e-3, 5e-4, -1e-4, 0.0, 2e-3])
    pts = np.column_stack([(R + depth) * np.sin(theta), (R + depth) * np.cos(theta) - R])
    X = np.column_stack([pts, np.tile(nodes.ravel(), (7, 1))])
    err = np.abs(_blended(X)[0] - depth)
    bound = spacing**2 / (8 * R)  # a tangent line's distance from the arc half a spacing away
    assert np.max(err) <= bound * (1 + spacing / R)  # to leading order in spacing / R
    assert np.max(err) > 0.9 * bound  # and reached at mid-segment: the bound is the error


def test_gap_and_force_are_continuous_where_a_slave_passes_a_master_node():
    # reference: the same evaluation just before and after the node, and the energy's FD
    x_ref, ns, anchor = _chain(slaves=np.array([[1.0, 0.0]]))
    pair = _pair(ns, 13, anchor)
    u = np.zeros((14, 2))
    u[1:, 1] = 0.02 * np.sin(x_ref[1:, 0])  # a wavy core lip: tangent lines differ per node
    u[0, 1] = u[1 + 6, 1] - 1e-3  # slave pressed into the lip near master node 6 (x = 3)

    def at(dx):
        u[0, 0] = dx
        return ct.evaluate(pair, x_ref, u)

    lo, hi = 1.8, 2.2  # the slave at x = 2.8 .. 3.2: on segment (5, 6), then on (6, 7)
    assert at(lo).segment[0] == 5 and at(hi).segment[0] == 6
    for _ in range(60):  # where it changes segment
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if at(mid).segment[0] == 5 else (lo, mid)
    before, after = at(lo), at(hi)
    assert before.segment[0] == 5 and after.segment[0] == 6
    assert before.gap[0] == pytest.approx(after.gap[0], abs=1e-10)
    assert np.allclose(before.nodal_forces(14), after.nodal_forces(14), atol=1e-6)


def test_evaluate_forces_and_tangent_are_derivatives_of_the_contact_energy_while_sliding():
    # reference: central differences of Π = ½ k b Σ w ⟨−g⟩² (forces) and of the forces (tangent)
    # over every node of a chain whose slaves slid one to three segments on a wavy lip, the
    # last one past the chain's end
    rng = np.random.default_rng(3)
    x_ref, ns, anchor = _chain()
    n_nodes = ns + 13
    pair = _pair(ns, 13, anchor, x_ref=x_ref[:ns, 0])
    u = np.zeros((n_nodes, 2))
    u[ns:, 1] = 0.03 * np.sin(1.3 * x_ref[ns:, 0])
    u[:ns, 0] = rng.uniform(0.6, 1.4, ns)  # slid 0.6 to 1.4 mm: 1 to 3 segments of 0.5 mm
    u[:ns, 1] = 0.03 * np.sin(1.3 * (x_ref[:ns, 0] + u[:ns, 0])) + rng.uniform(-4e-3, 2e-3, ns)
    st = ct.evaluate(pair, x_ref, u)
    assert 0 < len(st.active) < ns
    assert np.all(st.segment > anchor + 0)  # every slave on a segment ahead of its anchor
    assert np.all(st.slip > 0.5) and st.xi.max() > 1.0  # one slave past the last master node

    def energy(v):
        gaps = ct.evaluate(pair, x_ref, v.reshape(n_nodes, 2), want_tangent=False).gap
        return 0.5 * 50.0 * 2.0 * np.sum(0.7 * np.minimum(gaps, 0.0) ** 2)

    def force(v):
        return ct.evaluate(pair, x_ref, v.reshape(n_nodes, 2),
                           want_tangent=False).nodal_forces(n_nodes).ravel()

    h = 1e-7
    E = np.eye(2 * n_nodes)
    fd = np.array([(energy(u.ravel() + h * E[i]) - energy(u.ravel() - h * E[i])) / (2 * h)
                   for i in range(2 * n_nodes)])
    assert np.allclose(st.nodal_forces(n_nodes).ravel(), fd, rtol=1e-6, atol=1e-8)
    K = np.zeros((2 * n_nodes, 2 * n_nodes))
    dofs = (2 * st.rows[:, :, None] + np.arange(2)).reshape(len(st.rows), -1)
    for blk, d in zip(st.tangents, dofs, strict=True):
        np.add.at(K, (d[:, None], d[None, :]), blk)  # a node twice at the chain's end: summed
    h = 1e-6
    fdK = np.array([(force(u.ravel() + h * E[i]) - force(u.ravel() - h * E[i])) / (2 * h)
                    for i in range(2 * n_nodes)]).T
    assert np.allclose(K, fdK, rtol=1e-5, atol=1e-3)
    assert np.allclose(K, K.T)


def test_patch_a_face_sliding_several_segments_transmits_the_pressure_exactly():
    # reference (closed form): a face lip slid 1.7 mm (3.4 master segments) along a flat core
    # lip at 30°, pressed δ into it: p = k δ on every slave, the force k δ b w normal to the lip
    # on each, nothing tangential, and the opposite total force on the core
    angle = np.radians(30.0)
    t, n = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
    s_master = 0.5 * np.arange(17)
    s_slave = 0.5 * np.arange(2, 13)  # inner lip nodes (their anchors 2..12)
    x_ref = np.vstack([np.outer(s_slave, t), np.outer(s_master, t)])
    ns, n_nodes = len(s_slave), len(s_slave) + 17
    k, b, delta = 80.0, 3.0, 2e-3
    w = ct.slave_weights(s_slave, 0.0, 8.0)
    pair = ct.ContactPair(np.arange(ns), np.arange(17) + ns, np.arange(2, 13), w, k, b, s_slave)
    u = np.zeros((n_nodes, 2))
    u[:ns] = 1.7 * t - delta * n
    st = ct.evaluate(pair, x_ref, u)
    assert np.allclose(st.slip, 1.7, atol=1e-12)
    assert np.allclose(st.pressure, k * delta, rtol=1e-10)
    f = st.nodal_forces(n_nodes)
    assert np.allclose(f[:ns], -np.outer(k * delta * b * w, n), rtol=1e-10, atol=1e-12)
    assert np.allclose(f[ns:].sum(axis=0), k * delta * b * w.sum() * n, rtol=1e-10)
    assert abs(f[ns:].sum(axis=0) @ t) < 1e-12 * k * delta * b * w.sum()


def test_a_slave_sliding_out_of_its_window_is_reported_and_the_window_widened():
    x_ref, ns, anchor = _chain(n_master=41, slaves=np.array([[1.0, 0.0]]))
    pair = _pair(ns, 41, anchor)
    assert tuple(pair.window[0]) == (0, 2 + ct.WINDOW)
    u = np.zeros((42, 2))
    u[0] = [0.5 * ct.WINDOW + 1.2, -1e-3]  # past the window's last node
    st = ct.evaluate(pair, x_ref, u)
    assert list(st.outside) == [0]
    pair.widen(st)
    assert pair.window[0, 1] == st.spans[0, 1] + ct.WINDOW
    assert len(ct.evaluate(pair, x_ref, u).outside) == 0
    u[0, 1] = 1e-3  # an open slave takes no slots: never outside
    assert len(ct.evaluate(pair, x_ref, u).outside) == 0

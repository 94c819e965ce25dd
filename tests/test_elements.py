"""Invariants of the generated Timoshenko shaft element and rigid disk."""

import math
import re

import numpy as np
import pytest
from scipy.optimize import brentq

from rotorred._generated import timoshenko as gen
from rotorred.checks import InputError
from rotorred.model.elements import Disk, Material, ShaftElement, shear_coefficient

STEEL = Material("steel", E=2.1e11, rho=7850.0, nu=0.3)

# (L, D_o, D_i): slender solid, stubby solid (large phi), thin tube
SECTIONS = [(0.1, 0.02, 0.0), (0.02, 0.06, 0.0), (0.05, 0.065, 0.055)]


@pytest.fixture(params=[(s, f) for f in ("nelson", "hierarchical") for s in SECTIONS],
                ids=[f"{f}-{n}" for f in ("nelson", "hierarchical") for n in ("slender", "stubby", "tube")])
def element(request):
    (L, D_o, D_i), formulation = request.param
    return ShaftElement(1, 2, L, D_o, D_i, STEEL, element=formulation)


def rigid_body_vectors(L, n_internal=0):
    """Translations in x and y, rotations about x and y, in element DOFs (bubbles at rest:
    both interpolations hold every rigid motion with zero internal amplitudes)."""
    pad = [0.0] * n_internal
    tx = np.array([1, 0, 0, 0, 1, 0, 0, 0] + pad, float)
    ty = np.array([0, 1, 0, 0, 0, 1, 0, 0] + pad, float)
    # rotation about y by 1 rad: x = z, theta_y = 1 ; about x: y = -z, theta_x = 1
    ry = np.array([0, 0, 0, 1, L, 0, 0, 1] + pad, float)
    rx = np.array([0, 0, 1, 0, 0, -L, 1, 0] + pad, float)
    return [tx, ty, rx, ry]


def test_symmetry_and_skewness(element):
    M, K, G = element.M(), element.K(), element.G()
    scale = np.abs(M).max(), np.abs(K).max(), np.abs(G).max()
    assert np.allclose(M, M.T, rtol=0, atol=1e-14 * scale[0])
    assert np.allclose(K, K.T, rtol=0, atol=1e-14 * scale[1])
    assert np.allclose(G, -G.T, rtol=0, atol=1e-14 * scale[2])
    assert np.abs(G).max() > 0


def test_mass_positive_definite(element):
    assert np.linalg.eigvalsh(element.M()).min() > 0


def test_rigid_body_modes_in_null_space(element):
    K = element.K()
    for r in rigid_body_vectors(element.L, element.n_internal):
        # round-off of an 8x8 product of entries up to |K|max: 1e-12 relative
        assert np.abs(K @ r).max() < 1e-12 * np.abs(K).max() * max(1.0, element.L)


def test_stiffness_has_exactly_four_rigid_modes(element):
    ev = np.linalg.eigvalsh(element.K())
    assert np.sum(np.abs(ev) < 1e-10 * ev.max()) == 4


def test_translation_mass_is_rho_A_L(element):
    M = element.M()
    for r in rigid_body_vectors(element.L, element.n_internal)[:2]:
        assert r @ M @ r == pytest.approx(element.mass, rel=1e-13)


@pytest.mark.parametrize("formulation", ["nelson", "hierarchical"])
def test_rigid_rotation_inertia(formulation):
    # A rigid rotation about the element's left end: r^T M r = rho A L^3 / 3 + rho I L
    # (translational second moment plus the rotary inertia of the sections).
    e = ShaftElement(1, 2, 0.1, 0.03, 0.01, STEEL, element=formulation)
    for r in rigid_body_vectors(e.L, e.n_internal)[2:]:
        expected = STEEL.rho * e.A * e.L**3 / 3 + STEEL.rho * e.I * e.L
        assert r @ e.M() @ r == pytest.approx(expected, rel=1e-12)


def test_euler_bernoulli_limit():
    """phi = 0 gives the textbook consistent Euler-Bernoulli matrices (Przemieniecki 1968)."""
    L, rho, A, E, I = 0.3, 7800.0, 2e-4, 2e11, 3e-9
    Mt = gen.timoshenko_mass_translational(L, rho, A, 0.0)
    Mr = gen.timoshenko_mass_rotary(L, rho, I, 0.0)
    K = gen.timoshenko_stiffness(L, E, I, 0.0)
    # x-z plane DOFs (x1, theta_y1, x2, theta_y2) = indices (0, 3, 4, 7)
    xz = np.ix_([0, 3, 4, 7], [0, 3, 4, 7])
    Mt_eb = rho * A * L / 420 * np.array([[156, 22 * L, 54, -13 * L], [22 * L, 4 * L**2, 13 * L, -3 * L**2],
                                          [54, 13 * L, 156, -22 * L], [-13 * L, -3 * L**2, -22 * L, 4 * L**2]])
    Mr_eb = rho * I / (30 * L) * np.array([[36, 3 * L, -36, 3 * L], [3 * L, 4 * L**2, -3 * L, -L**2],
                                           [-36, -3 * L, 36, -3 * L], [3 * L, -L**2, -3 * L, 4 * L**2]])
    K_eb = E * I / L**3 * np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                                    [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L**2, -6 * L, 4 * L**2]])
    np.testing.assert_allclose(Mt[xz], Mt_eb, rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(Mr[xz], Mr_eb, rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(K[xz], K_eb, rtol=1e-13, atol=1e-6)
    # y-z plane: (y, -theta_x) behaves as (x, theta_y)
    S = np.diag([1.0, -1.0, 1.0, -1.0])
    yz = np.ix_([1, 2, 5, 6], [1, 2, 5, 6])
    np.testing.assert_allclose(S @ K[yz] @ S, K_eb, rtol=1e-13, atol=1e-6)
    np.testing.assert_allclose(S @ Mt[yz] @ S, Mt_eb, rtol=1e-13, atol=1e-16)


def test_small_phi_converges_to_euler_bernoulli():
    L, E, I = 0.3, 2e11, 3e-9
    K0 = gen.timoshenko_stiffness(L, E, I, 0.0)
    errs = [np.abs(gen.timoshenko_stiffness(L, E, I, p) - K0).max() for p in (1e-2, 1e-3, 1e-4)]
    assert errs[0] > errs[1] > errs[2] and errs[2] < 1e-3 * np.abs(K0).max()


@pytest.mark.parametrize("formulation", ["nelson", "hierarchical"])
def test_cantilever_tip_deflection_is_exact_timoshenko(formulation):
    """One element reproduces the exact static Timoshenko cantilever (both interpolations hold
    the exact static solution, a cubic w with quadratic psi):
    delta = P L^3 / (3 E I) + P L / (kappa G A) (shear adds the second term)."""
    e = ShaftElement(1, 2, 0.05, 0.06, 0.02, STEEL, element=formulation)
    K = e.K()
    free = [4, 7] + list(range(8, 8 + e.n_internal))  # x2, theta_y2 and bubbles (node 1 clamped)
    P = 1000.0
    f = np.zeros(len(free))
    f[0] = P
    u = np.linalg.solve(K[np.ix_(free, free)], f)
    exact = P * e.L**3 / (3 * STEEL.E * e.I) + P * e.L / (e.kappa * STEEL.G_s * e.A)
    assert u[0] == pytest.approx(exact, rel=1e-12)
    # and shear matters here (stubby element): more than 5 % of the deflection
    assert P * e.L / (e.kappa * STEEL.G_s * e.A) > 0.05 * exact


def test_gyroscopic_coupling_of_rigid_tilt_is_polar_inertia(element):
    """For the rigid rotations r_x, r_y the section rotations are uniform (theta_x = 1, resp.
    theta_y = 1, exactly, as the interdependent interpolation contains every rigid motion), so
    r_x^T G r_y = int 2 rho I dz = 2 rho I L: the element's polar inertia, as I_p for a disk."""
    _, _, rx, ry = rigid_body_vectors(element.L, element.n_internal)
    polar = 2 * element.material.rho * element.I * element.L
    assert rx @ element.G() @ ry == pytest.approx(polar, rel=1e-12)
    assert ry @ element.G() @ rx == pytest.approx(-polar, rel=1e-12)


def test_spin_acceleration_matrix_is_the_gyroscopic_energy_form(element):
    """K_G = A of G = A - A^T (docs/model.md, Eq. R2): its skew part is G, and on the rigid tilts
    (uniform theta_x = 1, resp. theta_y = 1) the form int 2 rho I theta_x theta_y dz gives
    r_x^T K_G r_y = 2 rho I L (the polar inertia) and r_y^T K_G r_x = 0 (theta_x of r_y is zero)."""
    K_G, G = element.K_G(), element.G()
    np.testing.assert_allclose(K_G - K_G.T, G, rtol=0, atol=1e-15 * np.abs(G).max())
    _, _, rx, ry = rigid_body_vectors(element.L, element.n_internal)
    polar = 2 * element.material.rho * element.I * element.L
    assert rx @ K_G @ ry == pytest.approx(polar, rel=1e-12)
    assert abs(ry @ K_G @ rx) < 1e-12 * polar
    # not skew: a symmetric part the gyroscopic matrix does not show (it acts only when Omega varies)
    assert np.abs(K_G + K_G.T).max() > 0.1 * np.abs(K_G).max()


def test_disk_matrices():
    d = Disk(3, m=2.0, I_d=0.01, I_p=0.02)
    np.testing.assert_array_equal(d.M(), np.diag([2.0, 2.0, 0.01, 0.01]))
    G = d.G()
    assert G[2, 3] == 0.02 and G[3, 2] == -0.02 and np.count_nonzero(G) == 2
    K_G = d.K_G()  # Id theta_x'' + I_p Omega theta_y' + I_p Omega' theta_y = M_x
    assert K_G[2, 3] == 0.02 and np.count_nonzero(K_G) == 1


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
def test_shear_coefficients(nu):
    # Solid circle: Cowper 6(1+nu)/(7+6nu), Hutchinson 6(1+nu)^2/(7+12nu+4nu^2) (published closed forms).
    assert shear_coefficient(1.0, 0.0, nu, "cowper") == pytest.approx(6 * (1 + nu) / (7 + 6 * nu), rel=1e-15)
    assert shear_coefficient(1.0, 0.0, nu, "hutchinson") == pytest.approx(
        6 * (1 + nu) ** 2 / (7 + 12 * nu + 4 * nu**2), rel=1e-15)
    # ROSS's line (ShaftElement, shear_method_calc="hutchinson") for a solid circle: 6(1+nu)/(7+12nu+4nu^2)
    assert shear_coefficient(1.0, 0.0, nu, "ross-hutchinson") == pytest.approx(
        6 * (1 + nu) / (7 + 12 * nu + 4 * nu**2), rel=1e-15)
    # Thin-walled tube limit (D_i -> D_o): Cowper 2(1+nu)/(4+3nu)
    assert shear_coefficient(1.0, 1.0 - 1e-9, nu, "cowper") == pytest.approx(2 * (1 + nu) / (4 + 3 * nu), rel=1e-8)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
@pytest.mark.parametrize("ratio", [0.0, 0.4, 0.8, 0.99])
def test_hutchinson_against_cowper(nu, ratio):
    """Both formulas coincide at nu = 0 (Hutchinson 2001, Sec. 5) and differ by under 10 % up to
    nu = 0.45. ROSS's line has (1+nu) where the published formula has (1+nu)^2 (shear =
    "ross-hutchinson"), which puts it 1.3x lower at nu = 0.3 and fails this comparison."""
    k_h = shear_coefficient(1.0, ratio, nu, "hutchinson")
    k_c = shear_coefficient(1.0, ratio, nu, "cowper")
    if nu == 0.0:
        assert k_h == pytest.approx(k_c, rel=1e-14)
    else:
        assert 1.0 < k_h / k_c < 1.10


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(L=-0.1), "L = -0.1: must be > 0 (m)"),
        (dict(L=0.0), "L = 0.0: must be > 0 (m)"),
        (dict(D_i=0.05), "D_i = 0.05: must be < D_o = 0.05 (m)"),
        (dict(D_i=0.06), "D_i = 0.06: must be < D_o = 0.05 (m)"),
        (dict(D_o=float("nan")), "D_o = nan: must be a finite number > 0 (m)"),
        (dict(shear="reissner"),
         "shear = 'reissner': must be one of 'cowper', 'hutchinson', 'ross-hutchinson', 'none'"),
        (dict(right=1), "right = 1: must differ from left = 1"),
        (dict(element="p5"), "element = 'p5': must be one of 'nelson', 'hierarchical'"),
        (dict(element="hierarchical", shear="none"), "element = 'hierarchical': must be 'nelson' with shear = 'none'"),
        (dict(left=-1), "left = -1: must be an integer >= 0"),
        (dict(material="steel"), "material = 'steel': must be a Material"),
    ],
)
def test_bad_shaft_element(kwargs, message):
    base = dict(left=1, right=2, L=0.1, D_o=0.05, D_i=0.0, material=STEEL)
    base.update(kwargs)
    with pytest.raises(InputError, match="^" + re.escape(message)):
        ShaftElement(**base)


@pytest.mark.parametrize("kwargs, message", [(dict(rho=-1.0), "rho = -1.0: must lie in [1e-09, 1e+06] (kg/m^3)"),
                                             (dict(E=0.0), "E = 0.0: must lie in (0, 1e+18] (Pa)"),
                                             (dict(nu=0.6), "nu = 0.6: must lie in (-1, 0.5)")])
def test_bad_material(kwargs, message):
    base = dict(name="s", E=2e11, rho=7800.0, nu=0.3)
    base.update(kwargs)
    with pytest.raises(InputError, match="^" + re.escape(message) + "$"):
        Material(**base)


def test_checked_values_are_stored_converted():
    """Integers given for lengths are stored as floats, numpy integers for nodes as int."""
    e = ShaftElement(np.int64(1), 2, 1, 1, 0, STEEL)
    assert type(e.left) is int and type(e.L) is float and type(e.D_i) is float
    assert e == ShaftElement(1, 2, 1.0, 1.0, 0.0, STEEL)


@pytest.mark.parametrize("shear", ["cowper", "none"])
@pytest.mark.parametrize("n", [1, 3])
def test_timoshenko_cantilever_tip_deflection(shear, n):
    """A stubby cantilever (L = 0.1 m, D = 50/10 mm) of n assembled elements under a tip load: the tip deflects
    P L^3 / 3EI + P L / (kappa G A) (bending plus shear; the shear part is 13.6 % here, so a wrong phi fails).
    Nelson's interdependent element is exact for a static end load at any n. Replaces a test that restated
    the code's formula for phi."""
    from rotorred.model.assembly import assemble
    from rotorred.model.rotor import Rotor, Spool

    L, P = 0.1, 1000.0
    els = tuple(ShaftElement(i, i + 1, L / n, 0.05, 0.01, STEEL, shear=shear) for i in range(1, n + 1))
    K = assemble(Rotor(spools=(Spool("s", els),))).K
    K = np.asarray(K.toarray() if hasattr(K, "toarray") else K)
    free = np.arange(4, K.shape[0])  # node 1 clamped
    f = np.zeros(len(free))
    f[-4] = P  # x of the tip node
    tip = np.linalg.solve(K[np.ix_(free, free)], f)[-4]
    e = els[0]
    ref = P * L**3 / (3 * STEEL.E * e.I) + (P * L / (e.kappa * STEEL.G_s * e.A) if shear != "none" else 0.0)
    assert (e.phi == 0.0) == (shear == "none")
    # measured within 4e-15 relative (round-off of the solve)
    assert tip == pytest.approx(ref, rel=5e-14)
    assert math.isclose(e.A, math.pi * (0.05**2 - 0.01**2) / 4)


def test_euler_bernoulli_without_rotary_inertia_is_the_textbook_beam():
    """shear = "none", rotary_inertia = False: the free-free beam's bending frequencies converge to the closed
    form w_n = (beta_n L)^2 sqrt(E I / (rho A L^4)), beta_n L the roots of cos(x) cosh(x) = 1 (brentq), at the
    cubic element's O(h^4): measured order 3.97 from 16 to 32 elements, error 2.5e-6 at 32 (3.8-4.2 and
    2.5e-5 allowed). With rotary inertia (Rayleigh beam) the limit is another, lower one: 8.4e-3 away at
    16 elements, 200x the discretisation error. No rotary mass, no shaft gyroscopic matrix."""
    import scipy.linalg as sla

    from rotorred.model.assembly import assemble
    from rotorred.model.rotor import Rotor, Spool

    steel = Material("steel", E=2.1e11, rho=7850.0, nu=0.3)
    L, D = 1.0, 0.05
    A, I = math.pi * D ** 2 / 4, math.pi * D ** 4 / 64
    roots = [brentq(lambda x: math.cos(x) * math.cosh(x) - 1.0, a, b) for a, b in ((4, 5), (7, 8.5))]
    exact = np.array([r ** 2 * math.sqrt(steel.E * I / (steel.rho * A * L ** 4)) for r in roots])

    def bending(n: int, rotary: bool) -> np.ndarray:
        els = tuple(ShaftElement(i, i + 1, L / n, D, 0.0, steel, shear="none", rotary_inertia=rotary)
                    for i in range(n))
        sm = assemble(Rotor((Spool("s", els),), name="beam"))
        w = np.sqrt(np.abs(sla.eigh(sm.K, sm.M, eigvals_only=True)))
        return w[4:8:2]  # after 4 rigid-body modes; each bending frequency in x and in y

    errors = [np.max(np.abs(bending(n, False) / exact - 1)) for n in (16, 32)]
    order = math.log2(errors[0] / errors[1])
    assert 3.8 < order < 4.2 and errors[1] < 2.5e-5
    rayleigh = np.max(np.abs(bending(16, True) / exact - 1))
    assert rayleigh > 100 * errors[0]
    e = ShaftElement(0, 1, 0.1, D, 0.0, steel, shear="none", rotary_inertia=False)
    assert not np.any(e.G()) and np.allclose(e.M(), ShaftElement(0, 1, 0.1, D, 0.0, steel, shear="none").M() -
                                             gen.timoshenko_mass_rotary(0.1, steel.rho, I, 0.0), rtol=0, atol=1e-15)


def test_bearing_table_interpolates_linearly_and_holds_its_ends():
    """Between the table's speeds a coefficient is the straight line through its neighbours (a linear table is
    reproduced at any speed); outside, the end value is held (docs/model.md §10)."""
    from rotorred.model.elements import BearingTable

    speeds = (0.0, 100.0, 300.0)
    line = lambda w: 1e6 + 2e4 * w  # noqa: E731 - linear in speed: reproduced exactly by linear interpolation
    b = BearingTable(node=3, speeds=speeds, k_xx=tuple(line(w) for w in speeds), k_yx=(-1.0, -2.0, -4.0), c_yy=50.0)
    rng = np.random.default_rng(3)
    for w in rng.uniform(0.0, 300.0, 20):
        at = b.at(w)
        assert at.k_xx == pytest.approx(line(w), rel=1e-14)
        assert at.c_yy == 50.0 and at.node == 3 and b.covers(w)
    assert b.at(250.0).k_yx == pytest.approx(-3.5, rel=1e-15)  # a cross-coupled term may be negative
    assert b.at(1e4).k_xx == line(300.0) and not b.covers(1e4)  # held above the table
    with pytest.raises(InputError, match=r"^Omega = -1.0: must be >= 0 \(rad/s\)$"):
        b.at(-1.0)


@pytest.mark.parametrize("kwargs, message", [
    (dict(speeds=(0.0,)), r"^speeds = \(0.0,\): must be a 1-D array of at least 2 values \(rad/s\)$"),
    (dict(speeds=(0.0, 10.0), k_xx=(1.0, 2.0, 3.0)), r"^k_xx = \(1.0, 2.0, 3.0\): must be a 1-D array of 2 values \(N/m\)$"),
    (dict(speeds=(0.0, 10.0), c_xx=-1.0), r"^c_xx = -1.0: must be >= 0 \(N s/m\)$"),
    (dict(speeds=(5.0, 5.0)), r"^speeds = \(5.0, 5.0\): must be strictly increasing; entry 0 = 5 is followed by 5 "
                               r"\(rad/s\)$"),
])
def test_bearing_table_bad_input(kwargs, message):
    from rotorred.model.elements import BearingTable

    with pytest.raises(InputError, match=message):
        BearingTable(node=1, **kwargs)


def _fritsch_carlson(W, v, w):
    """The monotone piecewise cubic Hermite interpolant written out (Fritsch & Carlson 1980, with Fritsch & Butland's
    harmonic-mean slopes and the three-point end slopes of Moler, Numerical Computing with MATLAB, §3.4), at ``w``
    inside the table, and its two end slopes: an implementation independent of scipy's."""
    h, delta = np.diff(W), np.diff(v) / np.diff(W)
    d = np.zeros(len(W))
    for k in range(1, len(W) - 1):
        if delta[k - 1] * delta[k] > 0:
            w1, w2 = 2 * h[k] + h[k - 1], h[k] + 2 * h[k - 1]
            d[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k])
    for end, (h0, h1, d0, d1) in ((0, (h[0], h[1], delta[0], delta[1])), (-1, (h[-1], h[-2], delta[-1], delta[-2]))):
        slope = ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1)
        if np.sign(slope) != np.sign(d0):
            slope = 0.0
        elif np.sign(d0) != np.sign(d1) and abs(slope) > 3 * abs(d0):
            slope = 3 * d0
        d[end] = slope
    k = min(np.searchsorted(W, w, side="right") - 1, len(W) - 2)
    t, hk = (w - W[k]) / h[k], h[k]
    value = ((2 * t**3 - 3 * t**2 + 1) * v[k] + (t**3 - 2 * t**2 + t) * hk * d[k]
             + (-2 * t**3 + 3 * t**2) * v[k + 1] + (t**3 - t**2) * hk * d[k + 1])
    return value, d[0], d[-1]


def test_bearing_table_pchip_is_the_monotone_cubic_and_extrapolates_along_its_end_tangents():
    """``interpolation = "pchip"`` (ROSS 3's rule) equals the Fritsch-Carlson interpolant written out independently
    (measured: 4.9e-16 of the largest value); on a table that rises then levels off it never overshoots (a cubic
    spline through the same points falls between them), and ``extrapolate = "linear"`` follows the end tangents,
    ``"hold"`` keeps the end values."""
    from scipy.interpolate import CubicSpline

    from rotorred.model.elements import BearingTable

    W = np.array([50.0, 100.0, 200.0, 260.0, 400.0])
    k = np.array([2e6, 3e6, 4e6, 4.05e6, 4.1e6])  # rises, then levels off
    kxy = np.array([-2e4, 1e4, 3e4, -1e4, 5e3])  # changes direction: zero slopes at the turns
    table = dict(node=3, speeds=tuple(W), k_xx=tuple(k), k_xy=tuple(kxy), interpolation="pchip")
    b, held = BearingTable(**table, extrapolate="linear"), BearingTable(**table)
    inside = np.linspace(50.0, 400.0, 71)
    for column, name in ((k, "k_xx"), (kxy, "k_xy")):
        ref = np.array([_fritsch_carlson(W, column, w)[0] for w in inside])
        got = np.array([getattr(b.at(w), name) for w in inside])
        assert np.max(np.abs(got - ref)) <= 3e-15 * np.max(np.abs(column))
        _, d0, d1 = _fritsch_carlson(W, column, W[0])
        for w in (0.0, 20.0):
            assert getattr(b.at(w), name) == pytest.approx(column[0] + d0 * (w - W[0]), rel=1e-14)
            assert getattr(held.at(w), name) == column[0]
        assert getattr(b.at(600.0), name) == pytest.approx(column[-1] + d1 * 200.0, rel=1e-14)
        assert getattr(held.at(600.0), name) == column[-1]
    values = np.array([b.at(w).k_xx for w in inside])
    assert np.all(np.diff(values) >= 0.0) and values.max() <= k.max()
    assert np.diff(CubicSpline(W, k)(inside)).min() < -5e3  # the spline dips between rising points (-9.1e3 N/m)
    two = BearingTable(node=1, speeds=(0.0, 10.0), k_xx=(1.0, 3.0), interpolation="pchip", extrapolate="linear")
    assert two.at(5.0).k_xx == 2.0 and two.at(20.0).k_xx == 5.0  # 2 speeds: the straight line
    with pytest.raises(InputError, match=r"^interpolation = 'spline': must be one of 'linear', 'pchip'$"):
        BearingTable(node=1, speeds=(0.0, 10.0), interpolation="spline")


def test_tapered_element_with_equal_ends_is_the_uniform_element():
    """The generated tapered matrices (derivations/tapered.py) with a constant section, A1 = A2 = I1..I4 = 0 and
    kappa G = 12 E I / (phi A L^2), are the uniform element's: measured 2e-16 of the largest entry (the two
    derivations integrate the same energies); asserted 1e-14. The frustum's mass is rho pi L (D_l^2 + D_l D_r +
    D_r^2) / 12 (closed form) to 1.4e-16."""
    from rotorred._generated import tapered as tap

    L, rho, A, I, phi, E = 0.3, 7850.0, 1.2e-3, 4e-7, 0.05, 2.1e11
    kG = 12 * E * I / (phi * A * L**2)
    pairs = [(tap.tapered_mass_translational(L, rho, A, 0, 0, phi), gen.timoshenko_mass_translational(L, rho, A, phi)),
             (tap.tapered_mass_rotary(L, rho, I, 0, 0, 0, 0, phi), gen.timoshenko_mass_rotary(L, rho, I, phi)),
             (tap.tapered_stiffness(L, E, I, 0, 0, 0, 0, kG, A, 0, 0, phi), gen.timoshenko_stiffness(L, E, I, phi)),
             (tap.tapered_spin_acceleration(L, rho, I, 0, 0, 0, 0, phi), gen.timoshenko_spin_acceleration(L, rho, I, phi))]
    for tapered, uniform in pairs:
        assert np.abs(tapered - uniform).max() <= 1e-14 * np.abs(uniform).max()
    steel = Material("steel", E=E, rho=rho, nu=0.3)
    cone = ShaftElement(0, 1, 1.0, 0.06, 0.0, steel, D_o_right=0.03)
    assert cone.tapered and cone.mass == pytest.approx(rho * math.pi / 12 * (0.06**2 + 0.06 * 0.03 + 0.03**2), rel=1e-15)
    assert not ShaftElement(0, 1, 1.0, 0.06, 0.0, steel, D_o_right=0.06).tapered
    with pytest.raises(InputError, match=r"^element = 'hierarchical': must be 'nelson' for a tapered element"):
        ShaftElement(0, 1, 1.0, 0.06, 0.0, steel, element="hierarchical", D_o_right=0.03)


@pytest.mark.parametrize("shear, order, tol16", [("none", (3.8, 4.2), 1.2e-3), ("cowper", None, 1.2e-2)])
def test_conical_shaft_converges_to_the_limit_of_fine_stepped_meshes(shear, order, tol16):
    """A solid cone (D 60 -> 30 mm over 1 m) pinned at both ends, two independent paths to its frequencies: tapered
    elements (the conical element split along its line) and many uniform elements at the mid-section's diameter
    (a staircase, O(h^2)), 512 of them as the reference. Euler-Bernoulli: the tapered mesh converges at O(h^4),
    measured order 3.97 from 8 to 16 elements and 1.15e-4 from the reference at 16 (asserted 3.8-4.2 and 1.2e-3).
    Timoshenko with rotary inertia: the Nelson interpolation's O(h^2), 4.3e-3 and 1.1e-3 at 8 and 16 elements
    (asserted falling and 1.2e-2 at 16)."""
    import scipy.linalg as sla

    from rotorred.model.assembly import assemble
    from rotorred.model.elements import Support
    from rotorred.model.rotor import Rotor, Spool

    steel = Material("steel", E=2.1e11, rho=7850.0, nu=0.3)
    L, D_left, D_right = 1.0, 0.06, 0.03
    rotary = shear != "none"

    def frequencies(elements):
        n = len(elements)
        sm = assemble(Rotor((Spool("s", tuple(elements)),), supports=(Support(0, "pinned"), Support(n, "pinned"))))
        return np.sqrt(np.abs(sla.eigh(sm.K, sm.M, eigvals_only=True)))[0:6:2]

    def tapered(n):
        cone = ShaftElement(0, n, L, D_left, 0.0, steel, shear=shear, rotary_inertia=rotary, D_o_right=D_right)
        return frequencies(cone.split(n, list(range(1, n))))

    def stepped(n):
        return frequencies([ShaftElement(i, i + 1, L / n, D_left + (D_right - D_left) * (i + 0.5) / n, 0.0, steel,
                                         shear=shear, rotary_inertia=rotary) for i in range(n)])

    reference = stepped(512)
    errors = [np.max(np.abs(tapered(n) / reference - 1)) for n in (8, 16)]
    assert errors[1] < errors[0] and errors[1] < tol16
    if order:
        assert order[0] < math.log2(errors[0] / errors[1]) < order[1]


def test_bearing_table_extrapolates_linearly_when_asked():
    """``extrapolate = "linear"`` (ROSS's behaviour) continues the end segments: a linear table is reproduced beyond
    both ends; a direct damping coefficient extrapolated below zero is refused, naming the bearing and the speed; a
    direct stiffness below zero is kept (a seal's may be negative: ROSS's compressor example has two at standstill)."""
    from rotorred.model.elements import BearingTable

    line = lambda w: 1e6 + 2e4 * w  # noqa: E731
    speeds = (100.0, 200.0, 300.0)
    b = BearingTable(node=3, speeds=speeds, k_xx=tuple(line(w) for w in speeds), c_xx=(10.0, 20.0, 30.0),
                     extrapolate="linear")
    for w in (0.0, 50.0, 350.0, 1000.0):
        assert b.at(w).k_xx == pytest.approx(line(w), rel=1e-14)
    assert BearingTable(node=3, speeds=speeds, k_xx=tuple(line(w) for w in speeds)).at(0.0).k_xx == line(100.0)
    with pytest.raises(InputError, match=r"^extrapolate = 'linear': gives c_xx = -10 at 0 rad/s for the bearing at "
                                         r"node 3, below 0"):
        BearingTable(node=3, speeds=speeds, c_xx=(10.0, 30.0, 40.0), extrapolate="linear").at(0.0)
    assert BearingTable(node=3, speeds=speeds, k_yy=(10.0, 30.0, 40.0), extrapolate="linear").at(0.0).k_yy == -10.0
    with pytest.raises(InputError, match=r"^extrapolate = 'cubic': must be one of 'hold', 'linear'$"):
        BearingTable(node=3, speeds=speeds, extrapolate="cubic")

"""One contact law: the generated residual under the clamp (rotorred.transient.contact.normal_law) and the Eq. 12
force (disk_force), evaluated the same by Python and by their njit wraps in the kernel."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotorred.transient import kernel
from rotorred.transient.contact import RubPlate, disk_force, hunt_crossley, normal_law, rotor_force

LAW = dict(K_nr=4e9, c=0.8, lam=2e-8)


@pytest.mark.parametrize("delta,rate", [(-1e-6, 0.01), (0.0, 0.0), (3e-6, -1.25), (3e-6, -2.0)])
def test_clamp_gives_the_open_law(delta, rate):
    """No force when delta <= 0 or 1 + c rate <= 0: R = F, dR/dF = 1, dR/dp = dR/drate = 0 (Python and compiled)."""
    F = 12.5
    for law in (normal_law, kernel._normal_law):
        np.testing.assert_array_equal(law(F, delta, rate, LAW["K_nr"], LAW["c"], LAW["lam"]), [F, 1.0, 0.0, 0.0])


def test_law_and_its_tangent():
    """In contact R = F - K delta^1.5 (1 + c rate); its tangent equals central differences, with delta = p - w0 - lam F
    (so dR/dF carries lam dF/d(delta)); the compiled wrap gives the same numbers."""
    F, p, rate = 30.0, 6e-6, 0.02
    K, c, lam = LAW["K_nr"], LAW["c"], LAW["lam"]

    def R(F, p, rate):
        return normal_law(F, p - lam * F, rate, K, c, lam)[0]

    r = normal_law(F, p - lam * F, rate, K, c, lam)
    delta = p - lam * F
    assert r[0] == pytest.approx(F - K * delta**1.5 * (1 + c * rate), rel=1e-14)
    # central differences with steps of 1e-6 relative: measured agreement 4e-12 (dR/dF) to 3.6e-11 (dR/drate)
    for i, (dF, dp, dr) in enumerate(((1e-6 * F, 0, 0), (0, 1e-6 * p, 0), (0, 0, 1e-6))):
        h = dF + dp + dr
        fd = (R(F + dF, p + dp, rate + dr) - R(F - dF, p - dp, rate - dr)) / (2 * h)
        assert r[i + 1] == pytest.approx(fd, rel=4e-10)
    # the same generated code, compiled: round-off only (measured: identical)
    np.testing.assert_allclose(kernel._normal_law(F, delta, rate, K, c, lam), r, rtol=1e-15)
    # the Hertz force alone is the law at F = 0, lam = 0
    assert hunt_crossley(delta, rate, K, c)[0] == pytest.approx(K * delta**1.5 * (1 + c * rate), rel=1e-15)


def test_eq12_force_is_one_function_for_floats_arrays_and_the_kernel():
    """(F_x, F_y) = -P n + T t on floats, on arrays (broadcast), compiled in the kernel, and through rotor_force."""
    theta = 2.1
    c, s = math.cos(theta), math.sin(theta)
    n, t = np.array([c, s]), np.array([-s, c])
    P, T = 40.0, -7.5
    ref = -P * n + T * t
    assert disk_force(P, T, c, s) == pytest.approx(tuple(ref), rel=0, abs=1e-13)
    assert kernel._disk_force(P, T, c, s) == disk_force(P, T, c, s)
    assert rotor_force(RubPlate(theta=theta), P, T) == disk_force(P, T, c, s)
    Ps, Ts = np.array([0.0, 1.0, 40.0]), np.array([0.0, -0.2, -7.5])
    Fx, Fy = disk_force(Ps, Ts, c, s)
    assert Fx.shape == (3,) and (Fx[2], Fy[2]) == disk_force(P, T, c, s)

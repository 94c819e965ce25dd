"""Pinned and clamped supports (issue 18 item 10): the DOFs a support fixes are removed from the model, exactly
(docs/model.md §11). Checked against the beam's closed forms, against the stiff-bearing workaround they replace, and
through Campbell, Craig-Bampton, the harmonic response and the transient."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import brentq

from rotorred.checks import InputError
from rotorred.linear.campbell import campbell
from rotorred.linear.harmonic import steady_state
from rotorred.model.operating import Operating
from rotorred.linear.reduction import reduce_rotor
from rotorred.model.assembly import assemble
from rotorred.model.rigid import rigid_body_motions
from rotorred.model.elements import Bearing, Disk, Material, ShaftElement, Support
from rotorred.model.loads import Unbalance
from rotorred.model.rotor import Rotor, Spool
from rotor_files import assert_refused
from rotorred.model.rotor_file import rotor_from_toml
from rotorred.transient.newmark import Initial, Loads, Recording, simulate

STEEL = Material("steel", E=2.1e11, rho=7850.0, nu=0.3)
L, D = 1.0, 0.05
A, I = math.pi * D ** 2 / 4, math.pi * D ** 4 / 64
#: sqrt(E I / (rho A L^4)) (rad/s): the beam's frequency scale
SCALE = math.sqrt(STEEL.E * I / (STEEL.rho * A * L ** 4))


def beam(n: int, supports=(), bearings=(), rotary: bool = False, disks=()) -> Rotor:
    """A uniform steel shaft of n elements, nodes 0..n; Euler-Bernoulli (no shear, no rotary inertia) by default."""
    els = tuple(ShaftElement(i, i + 1, L / n, D, 0.0, STEEL, shear="none" if not rotary else "cowper",
                             rotary_inertia=rotary) for i in range(n))
    return Rotor((Spool("s", els),), supports=supports, bearings=bearings, disks=disks, name="beam")


def bending(rotor: Rotor) -> np.ndarray:
    """The three lowest bending frequencies at rest (rad/s), each taken once of its x, y pair."""
    sm = assemble(rotor)
    return np.sqrt(np.abs(sla.eigh(sm.K, sm.M, eigvals_only=True)))[0:6:2]


@pytest.mark.parametrize("ends, beta_L", [
    ("pinned-pinned", [k * math.pi for k in (1, 2, 3)]),
    ("clamped-free", [brentq(lambda x: math.cos(x) * math.cosh(x) + 1.0, a, b) for a, b in ((1, 3), (4, 5.5), (7, 8.5))]),
])
def test_supported_beam_converges_to_the_closed_form(ends, beta_L):
    """w_n = (beta_n L)^2 sqrt(E I / (rho A L^4)): beta_n L = n pi pinned-pinned, the roots of cos cosh = -1
    (brentq) clamped-free. The cubic element converges at O(h^4). Measured: orders 3.99 and 3.98 from 16 to 32
    elements, errors 5.2e-6 and 2.5e-6 at 32; asserted 3.9-4.1 and 5e-5. 17 nodes x 4 DOFs less the 4 fixed: 64 DOFs."""
    exact = np.array(beta_L) ** 2 * SCALE

    def supports(n):
        return (Support(0, "pinned"), Support(n, "pinned")) if ends == "pinned-pinned" else (Support(0, "clamped"),)

    errors = [np.max(np.abs(bending(beam(n, supports(n))) / exact - 1)) for n in (16, 32)]
    assert 3.9 < math.log2(errors[0] / errors[1]) < 4.1 and errors[1] < 5e-5
    assert assemble(beam(16, supports(16))).n_dof == 64


def test_a_pinned_support_is_the_limit_of_the_stiff_bearing_workaround():
    """The stiff bearings users wrote instead (k -> infinity at the pinned nodes) approach the exact support as 1/k:
    measured 1.1e-5 at k = 1e12 N/m and 1.2e-8 at 1e15 (where the ill-conditioning starts); asserted within 1e-4 and
    1.2e-7, and the gap shrinking at least 100-fold."""
    n = 16
    exact = bending(beam(n, (Support(0, "pinned"), Support(n, "pinned"))))
    gaps = [np.max(np.abs(bending(beam(n, bearings=(Bearing(node=0, k_xx=k, k_yy=k), Bearing(node=n, k_xx=k, k_yy=k))))
                          / exact - 1)) for k in (1e12, 1e15)]
    assert gaps[0] < 1e-4 and gaps[1] < 1.2e-7 and gaps[1] < gaps[0] / 100


def test_fixed_dofs_are_not_dofs_of_the_model():
    """A pinned node keeps its rotations; asking for its x names the node and the support, before any computation."""
    sm = assemble(beam(4, (Support(0, "pinned"), Support(4, "clamped"))))
    assert sm.n_dof == 5 * 4 - 2 - 4
    assert sm.dofs.is_fixed(0, "x") and not sm.dofs.is_fixed(0, "theta_x") and sm.dofs.is_fixed(4, "ty")
    assert sm.dofs.label(sm.dofs.index(0, "theta_x")) == "node 0 theta_x"
    assert list(sm.dofs.node_dofs(4)) == [] and len(sm.dofs.node_dofs(0)) == 2
    with pytest.raises(InputError, match=r"^node = 0: must be a node whose x is free; a support fixes x there"):
        sm.output_rows([(0, "x")])


def test_campbell_of_a_spinning_shaft_between_pinned_ends():
    """A spinning Timoshenko shaft with a disk, pinned at both ends: no rigid-body mode, and the stiff-bearing
    workaround's critical speeds approach the supported ones as 1/k. Measured: 1.06e-6 at k = 1e12 N/m, then 10 times
    less per decade to 1.06e-10 at 1e16; asserted 1.1e-5 and a 5-fold fall each decade. No bending mode of the
    workaround passes for a rigid-body mode: the rigid-body test is relative to the spool's own first elastic
    frequency (docs/model.md §20), where it was relative to the largest w^2 of the model, the bearings', and took the
    bending modes for rigid from 1e15 N/m on."""
    n = 8
    disk = (Disk(node=4, m=5.0, I_d=0.02, I_p=0.04),)
    speeds = Operating.line(np.linspace(0.0, 1500.0, 31))
    pinned = campbell(beam(n, (Support(0, "pinned"), Support(n, "pinned")), rotary=True, disks=disk), speeds, n_modes=4)
    assert pinned.rigid_modes == () and len(pinned.critical_speeds) == 2
    gaps = []
    for k in (1e12, 1e13, 1e14, 1e15, 1e16):
        stiff = campbell(beam(n, bearings=(Bearing(node=0, k_xx=k, k_yy=k), Bearing(node=n, k_xx=k, k_yy=k)),
                              rotary=True, disks=disk), speeds, n_modes=4)
        assert stiff.rigid_modes == ()
        assert [c.whirl for c in stiff.critical_speeds] == [c.whirl for c in pinned.critical_speeds]
        gaps.append(max(abs(x.speed / y.speed - 1) for x, y in zip(stiff.critical_speeds, pinned.critical_speeds)))
    assert gaps[0] < 1.1e-5 and all(b < a / 5 for a, b in zip(gaps, gaps[1:]))


def test_a_free_spool_beside_one_on_stiff_bearings_keeps_its_rigid_body_modes():
    """Two spools: the shaft above on bearings of 1e15 N/m, and a free steel shaft. The model's largest w^2 (3.9e15,
    the bearings') puts the free spool's rigid-body w^2 at round-off (up to 5e-6) and the held spool's bending at
    2.45e5; each is judged against its own spool's first elastic w^2: the free spool's four motions are rigid, the
    held spool's critical speeds are the pinned shaft's within 1.1e-8 (measured 1.06e-9)."""
    n = 8
    disk = (Disk(node=4, m=5.0, I_d=0.02, I_p=0.04),)
    held = beam(n, bearings=(Bearing(node=0, k_xx=1e15, k_yy=1e15), Bearing(node=n, k_xx=1e15, k_yy=1e15)),
                rotary=True, disks=disk)
    free = Spool("free", tuple(ShaftElement(i, i + 1, 0.1, 0.03, 0.0, STEEL) for i in range(20, 26)))
    rotor = dataclasses.replace(held, spools=(*held.spools, free))
    assert rigid_body_motions(assemble(rotor)).shape[1] == 4
    line = np.linspace(0.0, 1500.0, 31)
    both = campbell(rotor, Operating.line(line, ratios={"free": 1.0}), n_modes=8)
    pinned = campbell(beam(n, (Support(0, "pinned"), Support(n, "pinned")), rotary=True, disks=disk),
                      Operating.line(line), n_modes=4)
    assert both.rigid_modes and all(both.frequencies_hz[0, j] < 1e-3 for j in both.rigid_modes)
    assert [c.whirl for c in both.critical_speeds] == [c.whirl for c in pinned.critical_speeds]
    assert max(abs(x.speed / y.speed - 1) for x, y in zip(both.critical_speeds, pinned.critical_speeds)) < 1.1e-8


def test_supports_in_craig_bampton_harmonic_and_transient():
    """A shaft pinned at one end and clamped at the other, with a disk. Its Craig-Bampton model (boundary: the disk
    node) converges to the full model: the lowest four whirl frequencies at 300 rad/s within 6.3e-4, 5.3e-5, 6.0e-6
    with 6, 10, 14 modes (asserted: falling, and 6e-5 at 14). A transient started on the harmonic (unbalance)
    solution stays on it: 2.1e-6 of the amplitude over 0.5 s at dt = 2e-5 s (asserted 2e-5)."""
    n = 8
    disk = (Disk(node=4, m=5.0, I_d=0.02, I_p=0.04),)
    shaft = beam(n, rotary=True)
    rotor = Rotor(shaft.spools, disks=disk, supports=(Support(0, "pinned"), Support(n, "clamped")), rayleigh=(5.0, 0.0))
    full = assemble(rotor)
    Omega = {"s": 300.0}

    def whirl(model):
        m = model.M.shape[0]
        A = np.block([[np.zeros((m, m)), np.eye(m)],
                      [-np.linalg.solve(model.M, model.K), -np.linalg.solve(model.M, model.damping(Omega))]])
        w = np.sort(np.linalg.eigvals(A).imag)
        return w[w > 0][:4]

    errors = [np.max(np.abs(whirl(reduce_rotor(rotor, extra_nodes=[4], n_modes=k)) / whirl(full) - 1))
              for k in (6, 10, 14)]
    assert errors[0] > errors[1] > errors[2] and errors[2] < 6e-5
    unb = [Unbalance(4, 1e-4, 0.0)]
    X = steady_state(full, Operating.point(Omega), unb).phasors["s"]
    res = simulate(full, Operating.point(Omega), 0.5, 2e-5, loads=Loads(unb), recording=Recording([(4, "x")]),
                   start=Initial(q0=X.real, v0=-300.0 * X.imag))
    row = full.output_rows([(4, "x")])[0]
    reference = (row @ X * np.exp(1j * 300.0 * res.t)).real
    assert np.max(np.abs(res.outputs[(4, "x")] - reference)) < 2e-5 * abs(row @ X)


ROTOR_FILE = """
name = "pinned shaft"
[[material]]
name = "steel"
E = 2.1e11
rho = 7850.0
[[spool]]
name = "s"
first_node = 0
elements = [ { L = 0.125, D_o = 0.05, material = "steel", repeat = 8 } ]
[[support]]
node = 0
kind = "pinned"
[[support]]
node = 8
kind = "clamped"
"""


def test_rotor_file_supports():
    r = rotor_from_toml(ROTOR_FILE)
    assert [(s.node, s.kind, s.fixed) for s in r.supports] == [(0, "pinned", ("x", "y")),
                                                               (8, "clamped", ("x", "y", "theta_x", "theta_y"))]


@pytest.mark.parametrize("old, new, message", [
    ('kind = "clamped"', 'kind = "welded"', "bad.toml: support[1].kind = 'welded': must be one of 'pinned', 'clamped'"),
    ("node = 8", "node = 0", "bad.toml: support[1].node = 0: must not carry a second support (node 0 is already "
     "pinned)"),
    ("node = 8\n", "node = 9\n", "bad.toml: support[1].node = 9: must be a node of the rotor (0-8)"),
    ('[[support]]\nnode = 0', '[[bearing]]\nnode = 0\nk = 1e7\n[[support]]\nnode = 0',
     "bad.toml: bearing[0].node = 0: must not be a pinned node: the support fixes its x and y, so a bearing there "
     "would carry no motion"),
])
def test_rotor_file_bad_supports(old, new, message):
    assert_refused(ROTOR_FILE, old, new, message)


@pytest.mark.parametrize("ends", ["pinned-pinned", "clamped-free"])
def test_self_weight_deflection_equals_the_beam_formula(ends):
    """Gravity on a supported beam: the consistent load of the whole rotor, the fixed DOFs' share included (their
    mass moves with a rigid translation too), so the cubic element's nodal deflections are exact: midspan
    5 w L^4 / (384 E I) pinned-pinned, tip w L^4 / (8 E I) clamped-free, w = rho A g. Measured 3.5e-14 with 8
    elements (full and Craig-Bampton with every interior mode); asserted 1e-12. Without the fixed DOFs' share the
    midspan was 2.2 % short at 8 elements."""
    from rotorred.model.loads import gravity_force

    n, g = 8, 9.81
    w = STEEL.rho * A * g
    if ends == "pinned-pinned":
        rotor, node, exact = beam(n, (Support(0, "pinned"), Support(n, "pinned"))), n // 2, 5 * w * L ** 4 / (384 * STEEL.E * I)
    else:
        rotor, node, exact = beam(n, (Support(0, "clamped"),)), n, w * L ** 4 / (8 * STEEL.E * I)
    full = assemble(rotor)
    red = reduce_rotor(rotor, extra_nodes=[node], n_modes=full.n_dof - 4)  # the boundary: the node's 4 DOFs
    for model in (full, red):
        q = np.linalg.solve(model.K, gravity_force(model, g))
        assert (model.output_rows([(node, "y")]) @ q)[0] == pytest.approx(-exact, rel=1e-12)

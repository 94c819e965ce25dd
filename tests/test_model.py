"""Rotor model, DOF map and assembly invariants."""

import re

import numpy as np
import pytest

from rotorred.checks import InputError
from rotorred.model.assembly import assemble
from rotorred.model.elements import Bearing, Disk, IntershaftBearing, Material, ShaftElement
from rotorred.model.rotor_file import load_rotor
from rotorred.model.rotor import Rotor, Spool

STEEL = Material("steel", 2.1e11, 7850.0, 0.3)


@pytest.fixture(scope="module")
def rig():
    return load_rotor("seed-rig")


def test_rig_topology(rig):
    assert rig.spool("inner").nodes == tuple(range(1, 14))
    assert rig.spool("outer").nodes == tuple(range(14, 21))
    assert sorted(d.node for d in rig.disks) == [3, 11, 16, 18]
    assert sorted(b.node for b in rig.bearings) == [1, 13, 14]
    (ib,) = rig.intershaft_bearings
    assert {ib.node_a, ib.node_b} == {20, 9}
    # the inter-shaft bearing joins two nodes at the same axial position
    assert rig.positions[20] == pytest.approx(rig.positions[9])
    assert rig.speeds["inner"] == pytest.approx(2 * np.pi * 70)
    assert rig.speeds["outer"] == pytest.approx(2 * np.pi * 90)
    assert rig.disk_at(18).radius > 0


def test_assembled_invariants(rig):
    S = assemble(rig)
    assert np.allclose(S.M, S.M.T, atol=1e-14 * np.abs(S.M).max())
    assert np.allclose(S.K, S.K.T, atol=1e-14 * np.abs(S.K).max())
    assert np.allclose(S.C, S.C.T)
    for G in S.G.values():
        assert np.allclose(G, -G.T, atol=1e-14 * np.abs(G).max())
    assert np.linalg.eigvalsh(S.M).min() > 0
    assert np.linalg.eigvalsh(S.K).min() > 0  # supported: no rigid-body mode left
    # total translational mass: u = unit x translation of every node
    u = np.zeros(S.n_dof)
    u[S.dofs.nodal[:, 0]] = 1.0
    assert u @ S.M @ u == pytest.approx(rig.mass, rel=1e-12)


def test_gyroscopic_per_spool_lives_on_its_spool(rig):
    S = assemble(rig)
    inner = np.concatenate([S.dofs.node_dofs(n) for n in rig.spool("inner").nodes])
    outer = np.concatenate([S.dofs.node_dofs(n) for n in rig.spool("outer").nodes])
    assert np.abs(S.G["inner"][np.ix_(outer, outer)]).max() == 0
    assert np.abs(S.G["outer"][np.ix_(inner, inner)]).max() == 0
    speeds = {"inner": 100.0, "outer": 250.0}
    np.testing.assert_allclose(S.gyroscopic(speeds), 100.0 * S.G["inner"] + 250.0 * S.G["outer"])


def test_free_rotor_rigid_modes_in_null_space_of_K():
    """Without bearings, the four rigid motions (two translations, two tilts) of a spool are
    in the null space of K, also across an inter-shaft bearing when both spools move together."""
    rig = load_rotor("seed-rig")
    free = Rotor(rig.spools, rig.disks, (), rig.intershaft_bearings)
    S = assemble(free)
    z = free.positions
    for direction in ("x", "y"):
        u = np.zeros(S.n_dof)
        for n in free.nodes:
            u[S.dofs.index(n, direction)] = 1.0
        assert np.abs(S.K @ u).max() < 1e-12 * np.abs(S.K).max()  # round-off (measured 0)
    tilt = np.zeros(S.n_dof)  # rotation about y by 1 rad: x = z, theta_y = 1
    for n in free.nodes:
        tilt[S.dofs.index(n, "x")] = z[n]
        tilt[S.dofs.index(n, "theta_y")] = 1.0
    assert np.abs(S.K @ tilt).max() < 1e-12 * np.abs(S.K).max()  # round-off (measured 5e-17)


def test_refined_keeps_nodes_and_mass(rig):
    r4 = rig.refined(4)
    assert set(rig.nodes) <= set(r4.nodes)
    for n in rig.nodes:
        assert r4.positions[n] == pytest.approx(rig.positions[n], abs=1e-12)
    assert r4.mass == pytest.approx(rig.mass, rel=1e-12)
    assert len(r4.spool("inner").elements) == 4 * len(rig.spool("inner").elements)
    assert min(set(r4.nodes) - set(rig.nodes)) == max(rig.nodes) + 1
    S4 = assemble(r4)
    assert S4.n_dof == 4 * len(r4.nodes)


def test_refined_frequencies_converge(rig):
    """The rig's lowest non-spinning frequencies change by less on each refinement."""
    from scipy.linalg import eigh

    def f(r):
        S = assemble(r)
        return np.sqrt(eigh(S.K, S.M, eigvals_only=True, subset_by_index=(0, 7)))

    f1, f2, f4 = f(rig), f(rig.refined(2)), f(rig.refined(4))
    d12, d24 = np.abs(f2 / f1 - 1).max(), np.abs(f4 / f2 - 1).max()
    assert d24 < d12 / 3  # at least order ~1.6; Nelson element gives ~h^2 (test_convergence)


def test_hierarchical_internal_dofs_come_after_nodal():
    els = tuple(ShaftElement(i, i + 1, 0.1, 0.03, 0.0, STEEL, element="hierarchical") for i in range(3))
    S = assemble(Rotor((Spool("s", els),), bearings=(Bearing(k_xx=1e7, k_yy=1e7, node=0),)))
    assert S.n_dof == 4 * 4 + 3 * 6
    assert S.dofs.index(3, "theta_y") == 15
    assert S.dofs.label(16) == "internal 0"


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Spool("s", ()), "elements = (): must hold at least 1 entry, not 0"),
        (lambda: Spool("s", (ShaftElement(1, 2, 0.1, 0.02, 0, STEEL), ShaftElement(3, 4, 0.1, 0.02, 0, STEEL))),
         "elements[1].left = 3: must be 2, the right node of elements[0]: the elements form a chain"),
        (lambda: Spool("s", (ShaftElement(1, 2, 0.1, 0.02, 0, STEEL), ShaftElement(2, 1, 0.1, 0.02, 0, STEEL))),
         "elements[1].right = 1: must not repeat a node of the chain"),
        (lambda: Rotor(()), "spools = (): must hold at least one spool"),
        (lambda: Rotor((Spool("a", (ShaftElement(1, 2, 0.1, 0.02, 0, STEEL),)),),
                       disks=(Disk(7, 1.0, 0.01, 0.02),)), "disks[0].node = 7: must be a node of the rotor (1-2)"),
        (lambda: Rotor((Spool("a", (ShaftElement(1, 2, 0.1, 0.02, 0, STEEL),)),),
                       bearings=(Bearing(k_xx=1.0, node=9),)),
         "bearings[0].node = 9: must be a node of the rotor (1-2)"),
        (lambda: Rotor((Spool("a", (ShaftElement(1, 2, 0.1, 0.02, 0, STEEL),)),),
                       intershaft_bearings=(IntershaftBearing(node_a=1, node_b=2),)),
         "intershaft_bearings[0].node_b = 2: must be on another spool than node_a = 1 (both are on spool 'a'); "
         "an inter-shaft bearing joins two different spools"),
        (lambda: Rotor((Spool("a", (ShaftElement(1, 2, 0.1, 0.02, 0, STEEL),)),
                        Spool("b", (ShaftElement(2, 3, 0.1, 0.02, 0, STEEL),)))),
         "spools[1].nodes = (2, 3): must not include node 2, which belongs to spool 'a'"),
        (lambda: Rotor((Spool("a", (ShaftElement(1, 2, 0.1, 0.02, 0, STEEL),)),), rayleigh=(-1.0, 0.0)),
         "rayleigh[0] = -1.0: must be >= 0 (1/s)"),
        (lambda: Rotor((Spool("a", (ShaftElement(1, 2, 0.1, 0.02, 0, STEEL),)),), disks=(3,)),
         "disks[0] = 3: must be a Disk"),
        (lambda: Bearing(c_xx=-1.0, node=1), "c_xx = -1.0: must be >= 0 (N s/m)"),  # k_xx < 0: a seal's, allowed
        (lambda: Bearing(k_xx=1.0), "node = -1: must be an integer >= 0"),
        (lambda: IntershaftBearing(node_a=3, node_b=3), "node_b = 3: must differ from node_a = 3"),
        (lambda: Disk(1, m=-2.0, I_d=0.0, I_p=0.0), "m = -2.0: must be > 0 (kg)"),
        (lambda: load_rotor("seed-rig").refined(0), "n = 0: must be an integer >= 1"),
        (lambda: load_rotor("seed-rig").with_speeds({"fan": 1.0}), "speeds.fan = 1.0: unknown key; allowed keys are "
         "inner, outer"),
        (lambda: load_rotor("seed-rig").spool("fan"), "spool = 'fan': must be one of 'inner', 'outer'"),
        (lambda: load_rotor("seed-rig").disk_at(5), "node = 5: must carry a disk; disks are at nodes [3, 11, 16, 18]"),
    ],
)
def test_bad_model_input(make, message):
    with pytest.raises(InputError, match="^" + re.escape(message) + "$"):
        make()


def test_dofmap_errors(rig):
    S = assemble(rig)
    with pytest.raises(InputError, match=r"^node = 99: must be a node of the model \(1-20\)$"):
        S.dofs.index(99, "x")
    with pytest.raises(InputError, match=r"^direction = 'z': must be one of 'x', 'y', 'theta_x' \('tx'\)"):
        S.dofs.index(18, "z")
    with pytest.raises(InputError, match=r"^speeds\.fan = 1\.0: unknown key; allowed keys are inner, outer$"):
        S.gyroscopic({"fan": 1.0})
    with pytest.raises(InputError, match=r"^dof = 80: must be an integer in \[0, 79\]$"):
        S.dofs.label(80)
    assert S.dofs.index(18, "ty") == S.dofs.index(18, "theta_y")


def test_the_input_objects_show_themselves_in_a_few_lines_without_arrays(rig):
    """repr of a Rotor, a Spool, the assembled and the reduced system and a Scene: at most 15 lines, the type's name
    first, no array (printing a Rotor or a Scene dumped 6-7 kB before); they say what they are (names, node ranges,
    nominal speeds in rpm and rad/s, counts, DOFs, kept nodes, modes, contact, duration). The dataclass equality is
    kept."""
    import dataclasses

    from rotorred.linear.reduction import reduce
    from rotorred.scenes.schema import load_scene

    from results_checks import assert_short_repr
    from test_rotor_toml import python_rotor

    built = python_rotor()
    for rotor in (rig, built, rig.refined(3), load_rotor("ross-coaxial")):
        text = assert_short_repr(rotor)
        assert f"{rotor.name!r}" in text and "rpm" in text and "rad/s" in text
        assert all(f"spool {s.name!r}" in text for s in rotor.spools)
    assert "spool 'inner': nodes 1-13; 12 elements; 4200 rpm (439.823 rad/s)" in repr(rig)
    assert "4 disks, 3 bearings (0 tabulated against speed), 1 inter-shaft bearing" in repr(rig)
    assert "'low': nodes 1-2, 4-5, 9, 40; 5 elements (+ 3 sleeves)" in assert_short_repr(built.spool("low"))
    system = assemble(rig)
    assert "80 physical DOFs of rotor 'seed-rig'\n  20 shaft nodes x 4" in assert_short_repr(system)
    assert "spool 'outer', nominal 5400 rpm (565.487 rad/s)" in repr(system)
    assert "4 bearings tabulated against speed, at nodes 24-25, 40, 56" in assert_short_repr(assemble(built))
    reduced = reduce(system, boundary_nodes=[1, 9, 13, 14, 18, 20], n_modes=6)
    text = assert_short_repr(reduced)
    assert "30 coordinates = 24 boundary DOFs + 6 modes" in text and "kept nodes 1, 9, 13-14, 18, 20" in text
    assert "of 80 physical DOFs of rotor 'seed-rig'" in text and "M, K, C of shape (30, 30)" in text
    scene = load_scene("paper-rub")
    text = assert_short_repr(scene)
    assert "'paper-rub': rotor 'seed-rig'" in text and "contact: rub at node 18" in text and "duration" in text
    assert len(repr(rig)) < 1000 and len(repr(scene)) < 1000
    assert rig == load_rotor("seed-rig") and rig != dataclasses.replace(rig, name="other")
    assert scene == load_scene("paper-rub")

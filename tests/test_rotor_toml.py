"""Save what you load (issue 35, item 6): ``Rotor.to_toml`` writes a rotor file that ``load_rotor`` reads back to an
equal rotor and to identical assembled matrices, for every preset, the ROSS example files and a rotor built in
Python; written again, the file is the same text."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest

import rotorred
from rotorred.model.assembly import assemble
from rotorred.model.elements import (Bearing, BearingTable, Disk, IntershaftBearing, IntershaftBearingTable, Material,
                                     Pedestal, ShaftElement, Support)
from rotorred.model.loads import Unbalance
from rotorred.model.rotor import AnalysisDefaults, Rotor, Spool
from rotorred.model.rotor_file import load_rotor
from rotorred.model.rotor_writer import rotor_table, rpm_to_rad_s
from rotorred.writers import exact_in_unit

ROSS3 = Path(__file__).resolve().parents[1] / "validation" / "reference" / "ross3"
#: the rotors saved by ROSS 3 that rotorred reads (tests/test_ross_files.py)
ROSS_FILES = [ROSS3 / "rotor_example.toml", ROSS3 / "compressor_example.toml",
              *(ROSS3 / "extra" / f"{name}.toml" for name in ("tapered_rotor", "pedestal_rotor", "damped_rotor",
                                                              "frequency_rotor", "hutchinson_rotor"))]


def inexact(start: float, to_si, from_si) -> float:
    """The first float from ``start`` up that no number in the other unit reads back to (``to_si``): a value the
    writer must give in SI."""
    value = start
    while exact_in_unit(value, to_si, from_si(value)) is not None:
        value = math.nextafter(value, math.inf)
    return value


def python_rotor() -> Rotor:
    """A rotor no file made: three spools, non-consecutive node numbers, speeds and a phase that no rpm or degree
    number reads back to, materials by nu and by G, tapered, hierarchical, Euler-Bernoulli and Rayleigh elements,
    sleeves, tables against speed (linear and pchip) and against whirl frequency, tilt coefficients (isotropic, cross
    and tabulated; on a pedestal link), a pedestal, a support, inter-shaft bearings (one tabulated against another
    spool's speed), defaults, internal damping (viscous and hysteretic, on spools and overridden on elements and a
    sleeve)."""
    steel = Material("steel", E=2.07e11, rho=7833.4, nu=0.29)
    titanium = Material("Ti-6Al-4V", E=1.138e11, G=4.4e10, rho=4430.0)
    low = Spool("low", (ShaftElement(1, 2, 0.071, 0.031, 0.0, steel),
                        ShaftElement(2, 5, 0.071, 0.031, 0.0, steel, D_o_right=0.027, internal_loss_factor=0.013),
                        ShaftElement(5, 9, 0.09, 0.027, 0.011, titanium, shear="hutchinson"),
                        ShaftElement(9, 4, 0.09, 0.027, 0.011, titanium, element="hierarchical",
                                     internal_damping_beta=0.0),
                        ShaftElement(4, 40, 0.11, 0.025, 0.0, steel, shear="none", rotary_inertia=False)),
                speed=inexact(2 * math.pi * 73.3, rpm_to_rad_s, lambda w: w * 30 / math.pi), z0=-0.013,
                internal_damping_beta=2.1e-5,
                sleeves=(ShaftElement(5, 9, 0.09, 0.045, 0.027, steel, internal_damping_beta=3e-5),
                         ShaftElement(9, 4, 0.09, 0.045, 0.027, steel),
                         ShaftElement(1, 2, 0.071, 0.05, 0.031, titanium, D_i_right=0.033)))
    high = Spool("high", tuple(ShaftElement(n, n + 1, 0.05, 0.06, 0.045, titanium) for n in range(20, 25)),
                 speed=1234.5678, z0=0.1, internal_loss_factor=2e-3)
    fan = Spool("fan", (ShaftElement(60, 58, 0.2, 0.04, 0.0, steel), ShaftElement(58, 56, 0.2, 0.04, 0.0, steel)),
                z0=0.5)
    speeds = (0.0, 157.3, 1e3 / 3, 2 * math.pi * 97.1)
    return Rotor(
        spools=(low, high, fan),
        disks=(Disk(9, 3.3, 0.011, 0.02, name="fan", radius=0.11), Disk(22, 1.7, 4e-3, 7.9e-3),
               Disk(56, 0.4, 0.0, 0.0)),
        bearings=(Bearing(k_xx=3.1e7, k_yy=2.9e7, k_xy=-1.1e6, c_xx=410.0, c_yy=410.0, node=1, name="front"),
                  BearingTable(40, speeds, k_xx=(1e7, 2e7, 3e7, 3.5e7), k_yy=(1e7, 2e7, 3e7, 3.5e7), c_xx=300.0,
                               c_yy=(300.0, 280.0, 250.0, 240.0), k_yx=(0.0, 1e5, 4e5, 6e5), interpolation="pchip",
                               extrapolate="linear", name="fluid film"),
                  BearingTable(25, (10.0, 600.0), k_xx=5e6, k_yy=6e6, c_xy=(1.0, 2.0), link=70, k_txtx=(3e4, 4e4),
                               k_tyty=(3e4, 4e4), axis="frequency"),
                  Bearing(k_xx=1e8, k_yy=1e8, node=70),
                  Bearing(k_xx=2e7, k_yy=2e7, c_xx=50.0, c_yy=50.0, node=60, k_txtx=2e5, k_tyty=2e5, k_txty=-3e3,
                          c_txtx=4.0, c_tyty=4.5, c_tytx=0.5)),
        intershaft_bearings=(IntershaftBearing(k_xx=1e7, k_yy=1.2e7, c_xx=300.0, c_yy=300.0, node_a=20, node_b=5,
                                               name="inter-shaft", k_txtx=1e4, k_tyty=1e4),
                             IntershaftBearingTable(24, 9, speeds, k_xx=(1e6, 2e6, 3e6, 4e6), k_yy=2e6, c_xx=20.0,
                                                    c_yy=20.0, speed_of="low", interpolation="pchip",
                                                    c_txtx=(0.5, 0.6, 0.7, 0.8), c_tyty=(0.5, 0.6, 0.7, 0.8)),
                             IntershaftBearingTable(56, 2, (0.0, 600.0), k_xx=(1e5, 2e5), k_yy=(1e5, 2e5))),
        rayleigh=(3.0, 1.7e-6), name="built in Python",
        defaults=AnalysisDefaults(unbalances=(Unbalance(9, 2e-5, inexact(0.7, math.radians, math.degrees)),
                                              Unbalance(22, 1e-5, math.radians(30.0)), Unbalance(56, 3e-6)),
                                  outputs=((40, "x"), (22, "theta_y")), boundary_nodes=(4, 58)),
        supports=(Support(58, "pinned"),), pedestals=(Pedestal(70, 12.5, name="housing"),))


def assert_identical(a, b, where: str = "") -> None:
    """``a`` and ``b`` equal to the bit: arrays byte for byte, dataclasses field by field, mappings and sequences
    item by item."""
    if isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, where
        assert a.tobytes() == b.tobytes(), where
    elif hasattr(a, "toarray"):  # a sparse matrix
        assert_identical(a.toarray(), b.toarray(), where)
    elif dataclasses.is_dataclass(a):
        assert type(a) is type(b), where
        for f in dataclasses.fields(a):
            assert_identical(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, Mapping):
        assert list(a) == list(b), where
        for key in a:
            assert_identical(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(a, (tuple, list)):
        assert type(a) is type(b) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_identical(x, y, f"{where}[{i}]")
    else:
        assert type(a) is type(b) and a == b, f"{where}: {a!r} != {b!r}"
        if isinstance(a, float):
            assert math.copysign(1.0, a) == math.copysign(1.0, b), where


def round_trip(rotor: Rotor, tmp_path: Path) -> tuple[Rotor, str]:
    """The rotor written, read back and written again: the rotor read and the text, checked to be a fixed point."""
    first = rotor.to_toml(tmp_path / "first.toml")
    back = load_rotor(first)
    second = back.to_toml(tmp_path / "second.toml")
    assert second.read_text() == first.read_text()
    return back, first.read_text()


ROTORS = {**{f"preset {name}": (lambda name=name: load_rotor(name)) for name in rotorred.presets()},
          **{f"ROSS {p.stem}": (lambda p=p: load_rotor(p)) for p in ROSS_FILES},
          "seed-rig refined(3)": lambda: load_rotor("seed-rig").refined(3),
          "built in Python": python_rotor}


@pytest.mark.parametrize("name", list(ROTORS))
def test_to_toml_reads_back_the_same_rotor_and_the_same_matrices(name, tmp_path):
    """Every preset, every ROSS example file, a refined rotor (nodes numbered out of order) and the rotor built in
    Python read back from the file ``to_toml`` wrote as an equal rotor whose assembled matrices (M, K, C, G and
    K_G per spool, the DOF map, the tabulated supports, the supported weight) are identical to the bit; the file
    written again from the rotor read is the same text."""
    rotor = ROTORS[name]()
    back, _ = round_trip(rotor, tmp_path)
    assert back == rotor
    assert_identical(back, rotor)
    assert_identical(assemble(back), assemble(rotor))


def test_the_python_rotor_is_written_in_the_files_units_where_exact_and_in_si_where_not(tmp_path):
    """The speeds no rpm number reads back to, and the phase no degree number reads back to, are written in SI
    (``speed_rad_s``, ``phase_rad``); the others in rpm and degrees (30 degrees exactly); a spool numbered out of
    order lists its nodes; the material given by G keeps G, its nu derived on reading as before."""
    rotor = python_rotor()
    _, text = round_trip(rotor, tmp_path)
    low, high = text.split("[[spool]]")[1:3]
    assert f"speed_rad_s = {rotor.spool('low').speed!r}\n" in low and "speed_rpm" not in low
    assert "speed_rpm = " in high  # 1234.5678 rad/s reads back from an rpm number
    assert f"phase_rad = {rotor.defaults.unbalances[0].phase!r}\n" in text and "phase_deg = 30.0\n" in text
    assert "nodes = [1, 2, 5, 9, 4, 40]" in text and "nodes = [60, 58, 56]" in text and "first_node = 20" in text
    assert 'name = "Ti-6Al-4V"\nE = 113800000000.0\nrho = 4430.0\nG = 44000000000.0\n' in text
    assert "k_tt = 200000.0\nk_txty = -3000.0\nc_txtx = 4.0\nc_tyty = 4.5\nc_tytx = 0.5\n" in text
    assert 'speed_of = "low"\nspeed_rad_s = [0.0, 157.3, ' in text and "frequency_rpm = [" in text


def test_a_material_read_from_g_keeps_g_and_a_preset_is_written_in_its_own_units(tmp_path):
    """ross-coaxial's steel is given by G: written with G (nu derived again, not written); seed-rig's speeds are
    written as 4200.0 and 5400.0 rpm, its elements as runs (repeat = 12)."""
    text = load_rotor("ross-coaxial").to_toml(tmp_path / "coax.toml").read_text()
    assert "G = 81200000000.0" in text and "nu =" not in text
    text = load_rotor("seed-rig").to_toml(tmp_path / "rig.toml").read_text()
    assert "speed_rpm = 4200.0\n" in text and "speed_rpm = 5400.0\n" in text and "repeat = 12" in text


def test_materials_with_one_name_are_written_apart():
    """Two different materials of one name (possible in Python, not in a file) get names that differ: the second
    ``steel-2``; a material with no name is ``material``."""
    a, b, c = Material("steel", 2.1e11, 7850.0), Material("steel", 2.0e11, 7800.0), Material("", 1e11, 3000.0)
    spool = Spool("s", (ShaftElement(0, 1, 0.1, 0.02, 0.0, a), ShaftElement(1, 2, 0.1, 0.02, 0.0, b),
                        ShaftElement(2, 3, 0.1, 0.02, 0.0, c)))
    table = rotor_table(Rotor((spool,)))
    assert [m["name"] for m in table["material"]] == ["steel", "steel-2", "material"]
    assert [e["material"] for e in table["spool"][0]["elements"]] == ["steel", "steel-2", "material"]


def test_exact_in_unit_finds_the_shortest_number_that_reads_back():
    """4200 rpm in rad/s is written back as 4200.0 (not 4199.999999999999); a speed no rpm number reads back to gives
    None."""
    w = rpm_to_rad_s(4200.0)
    assert exact_in_unit(w, rpm_to_rad_s, w * 30 / math.pi) == 4200.0
    missed = inexact(100.0, rpm_to_rad_s, lambda v: v * 30 / math.pi)
    assert all(rpm_to_rad_s(math.nextafter(missed * 30 / math.pi, d)) != missed for d in (math.inf, -math.inf))

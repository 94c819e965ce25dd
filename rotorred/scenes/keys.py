"""How a varied scene key is shown and stored: its unit (``rub.clearance`` in µm, a speed in Hz), its CF units and
its NetCDF name.

Scene files hold SI values (speeds in Hz); plots and tables of a map show a key scaled to the
unit an engineer reads (:func:`key_unit`). A NetCDF file (``map.nc``, ``branch.nc``) names the key's dimension or
coordinate :func:`netcdf_name` (``rub.clearance`` -> ``rub_clearance``: CF names hold no dots), with the key's
:func:`cf_units` in the scene file's units (UDUNITS names, "1" for a dimensionless number).
"""

from __future__ import annotations

import re

__all__ = ["key_unit", "cf_units", "netcdf_name"]

#: how a varied scene key is shown, by its last name: (scale from the scene's unit, unit shown)
_KEY_UNITS = {"clearance": (1e6, "µm"), "m_e": (1.0, "kg m"), "dt": (1.0, "s"), "mu_s": (1.0, "-"),
              "mu_d": (1.0, "-"), "k_n": (1.0, "N/m"), "K_nr": (1.0, "N/m^1.5"), "theta_deg": (1.0, "deg")}

#: CF (UDUNITS) units of the numeric scene keys as a scene file writes them, by section and last name; "1" for a
#: dimensionless number, a count or a node number. ``rub.K_nr`` (N/m^1.5) has a fractional power, which UDUNITS
#: does not parse: it is written as the scene's docs write it.
_CF_UNITS = {
    "unbalance": {"m_e": "kg m", "phase_deg": "degree"},
    "rub": {"theta_deg": "degree", "clearance": "m", "K_nr": "N/m^1.5", "c": "s/m", "m_p": "kg", "k_n": "N/m",
            "k_t": "N/m", "c_n": "N s/m", "c_t": "N s/m", "disk_radius": "m", "plate_a": "m", "plate_b": "m",
            "plate_h": "m", "plate_E": "Pa", "plate_xi": "m", "plate_eta": "m", "a0": "N/m", "b0": "N"},
    "rotor": {"rayleigh_alpha": "s-1", "rayleigh_beta": "s"},
    "solver": {"cutoff_hz": "Hz", "dt": "s", "duration": "s", "record_start": "s", "gravity": "m s-2"},
    "output": {"f_max_hz": "Hz"},
    "runup": {"duration": "s", "hold": "s", "record_dt": "s", "orbits_hz": "Hz"},
}


def key_unit(key: str) -> tuple[float, str]:
    """(scale, unit) in which a varied scene key is shown: ``"rub.clearance"`` -> (1e6, "µm"), a speed in Hz."""
    if key.startswith("speeds."):
        return 1.0, "Hz"
    return _KEY_UNITS.get(key.split(".")[-1], (1.0, "scene units"))


def cf_units(key: str) -> str:
    """The CF ``units`` of a numeric scene key's values as the scene file writes them: ``"speeds.outer"`` -> "Hz",
    ``"rub[0].clearance"`` -> "m", ``"rub.mu_d"`` -> "1"; "1" for every dimensionless key (friction, Poisson's ratio,
    counts, node numbers, a run-up's fractions of the speeds)."""
    section, _, name = key.partition(".")
    section = section.partition("[")[0]
    if section == "speeds":
        return "Hz"
    return _CF_UNITS.get(section, {}).get(name, "1")


def netcdf_name(key: str) -> str:
    """The NetCDF (CF) name of a scene key: every run of characters other than letters, digits and ``_`` made one
    ``_`` (``"rub.clearance"`` -> ``"rub_clearance"``, ``"rub[1].k_n"`` -> ``"rub_1_k_n"``)."""
    name = re.sub(r"[^A-Za-z0-9_]+", "_", key).strip("_")
    return name if name[:1].isalpha() else f"key_{name}"

"""How a varied scene key is shown: its unit (``rub.clearance`` in µm, a speed in Hz).

Scene files hold SI values (speeds in Hz); plots and tables of a map show a key scaled to the
unit an engineer reads (:func:`key_unit`).
"""

from __future__ import annotations

__all__ = ["key_unit"]

#: how a varied scene key is shown, by its last name: (scale from the scene's unit, unit shown)
_KEY_UNITS = {"clearance": (1e6, "µm"), "m_e": (1.0, "kg m"), "dt": (1.0, "s"), "mu_s": (1.0, "-"),
              "mu_d": (1.0, "-"), "k_n": (1.0, "N/m"), "K_nr": (1.0, "N/m^1.5"), "theta_deg": (1.0, "deg")}


def key_unit(key: str) -> tuple[float, str]:
    """(scale, unit) in which a varied scene key is shown: ``"rub.clearance"`` -> (1e6, "µm"), a speed in Hz."""
    if key.startswith("speeds."):
        return 1.0, "Hz"
    return _KEY_UNITS.get(key.split(".")[-1], (1.0, "scene units"))

"""Model inputs: material, shaft element, rigid disk, bearing, inter-shaft bearing.

Each is a frozen dataclass validated at construction; a bad value raises ``ValueError``
naming the parameter, the value and what is allowed. Element matrices come from the
generated module :mod:`rotorred._generated.timoshenko` (``python -m derivations``).

DOF order at a node: (x, y, theta_x, theta_y); z is the shaft axis. A positive theta_y turns
z towards x, a positive theta_x turns z towards -y; a spool spins about +z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rotorred._generated import timoshenko as _gen

SHEAR_METHODS = ("cowper", "hutchinson", "none")
FORMULATIONS = ("nelson", "hierarchical")


def _positive(name: str, value: float, unit: str = "") -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ValueError(f"`{name}` must be a positive finite number{unit}, got {value!r}")


def _non_negative(name: str, value: float, unit: str = "") -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
        raise ValueError(f"`{name}` must be a finite number >= 0{unit}, got {value!r}")


def _finite(name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value)):
        raise ValueError(f"`{name}` must be a finite number, got {value!r}")


@dataclass(frozen=True)
class Material:
    """Isotropic linear-elastic material.

    Parameters
    ----------
    name : str
    E : float
        Young's modulus (Pa).
    rho : float
        Density (kg/m^3).
    nu : float
        Poisson's ratio (-), -1 < nu < 0.5.
    """

    name: str
    E: float
    rho: float
    nu: float = 0.3

    def __post_init__(self):
        _positive("E", self.E, " (Pa)")
        _positive("rho", self.rho, " (kg/m^3)")
        _finite("nu", self.nu)
        if not -1.0 < self.nu < 0.5:
            raise ValueError(f"`nu` must lie in (-1, 0.5), got {self.nu!r}")

    @property
    def G_s(self) -> float:
        """Shear modulus E / (2 (1 + nu)) (Pa)."""
        return self.E / (2.0 * (1.0 + self.nu))


def shear_coefficient(D_o: float, D_i: float, nu: float, method: str = "cowper") -> float:
    """Timoshenko shear coefficient kappa of a hollow circular section.

    Parameters
    ----------
    D_o, D_i : float
        Outer and inner diameter (m), 0 <= D_i < D_o.
    nu : float
        Poisson's ratio (-).
    method : {"cowper", "hutchinson"}
        ``"cowper"``: Cowper (1966), J. Appl. Mech. 33, Table 1, hollow circle,
        kappa = 6 (1+nu)(1+m^2)^2 / ((7+6nu)(1+m^2)^2 + (20+12nu) m^2), m = D_i/D_o.
        ``"hutchinson"``: Hutchinson (2001), J. Appl. Mech. 68, Eq. (52), hollow circle
        (a = outer, b = inner radius),
        kappa = 6 (a^2+b^2)^2 (1+nu)^2 / (7a^4 + 34a^2b^2 + 7b^4
        + nu (12a^4 + 48a^2b^2 + 12b^4) + nu^2 (4a^4 + 16a^2b^2 + 4b^4)).
        The (1+nu)^2 factor is part of the published formula (ROSS's line omits it).

    Returns
    -------
    float
    """
    if method == "cowper":
        m2 = (D_i / D_o) ** 2
        return 6.0 * (1 + nu) * (1 + m2) ** 2 / ((7 + 6 * nu) * (1 + m2) ** 2 + (20 + 12 * nu) * m2)
    if method == "hutchinson":
        a2, b2 = (D_o / 2) ** 2, (D_i / 2) ** 2
        num = 6.0 * (a2 + b2) ** 2 * (1 + nu) ** 2
        den = (7 * a2**2 + 34 * a2 * b2 + 7 * b2**2 + nu * (12 * a2**2 + 48 * a2 * b2 + 12 * b2**2)
               + nu**2 * (4 * a2**2 + 16 * a2 * b2 + 4 * b2**2))
        return num / den
    raise ValueError(f"`shear` must be one of {SHEAR_METHODS}, got {method!r}")


@dataclass(frozen=True)
class ShaftElement:
    """Uniform hollow circular Timoshenko shaft element between two nodes of one spool.

    Parameters
    ----------
    left, right : int
        Node numbers (as the user sees them), ``left`` at the smaller axial position.
    L : float
        Length (m).
    D_o : float
        Outer diameter (m).
    D_i : float
        Inner diameter (m), 0 <= D_i < D_o.
    material : Material
    shear : {"cowper", "hutchinson", "none"}
        Shear coefficient formula; ``"none"`` gives the Euler-Bernoulli element (phi = 0)
        with rotary inertia (Rayleigh beam).
    element : {"nelson", "hierarchical"}
        ``"nelson"`` (default): interdependent interpolation (Nelson 1980), 4 DOFs per node,
        exact in statics; its constant shear strain makes eigenvalues converge as h^2 with a
        small constant. ``"hierarchical"``: cubic displacement and quadratic rotation with 6
        internal bubble DOFs per element (``n_internal``); eigenvalues converge as h^4. See
        docs/model.md, "Shaft element".
    """

    left: int
    right: int
    L: float
    D_o: float
    D_i: float
    material: Material
    shear: str = "cowper"
    element: str = "nelson"

    def __post_init__(self):
        for name in ("left", "right"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 0:
                raise ValueError(f"`{name}` must be a node number (integer >= 0), got {value!r}")
        if self.left == self.right:
            raise ValueError(f"`left` and `right` must be different nodes, got {self.left} for both")
        _positive("L", self.L, " (m)")
        _positive("D_o", self.D_o, " (m)")
        _non_negative("D_i", self.D_i, " (m)")
        if self.D_i >= self.D_o:
            raise ValueError(f"`D_i` must be smaller than `D_o` = {self.D_o!r} m, got {self.D_i!r} m")
        if self.shear not in SHEAR_METHODS:
            raise ValueError(f"`shear` must be one of {SHEAR_METHODS}, got {self.shear!r}")
        if self.element not in FORMULATIONS:
            raise ValueError(f"`element` must be one of {FORMULATIONS}, got {self.element!r}")
        if self.element == "hierarchical" and self.shear == "none":
            raise ValueError('`element` "hierarchical" needs shear flexibility; use shear="cowper" or "hutchinson" '
                             '(or element="nelson" for an Euler-Bernoulli element)')

    @property
    def n_internal(self) -> int:
        """Number of internal (bubble) DOFs: 0 for ``"nelson"``, 6 for ``"hierarchical"``."""
        return 6 if self.element == "hierarchical" else 0

    @property
    def A(self) -> float:
        """Cross-section area (m^2)."""
        return math.pi * (self.D_o**2 - self.D_i**2) / 4.0

    @property
    def I(self) -> float:  # noqa: E743 - textbook symbol
        """Diametral second moment of area (m^4); the polar one is 2 I."""
        return math.pi * (self.D_o**4 - self.D_i**4) / 64.0

    @property
    def kappa(self) -> float:
        """Shear coefficient (-); inf for ``shear="none"``."""
        if self.shear == "none":
            return math.inf
        return shear_coefficient(self.D_o, self.D_i, self.material.nu, self.shear)

    @property
    def phi(self) -> float:
        """Shear parameter 12 E I / (kappa G A L^2) (-)."""
        if self.shear == "none":
            return 0.0
        mat = self.material
        return 12.0 * mat.E * self.I / (self.kappa * mat.G_s * self.A * self.L**2)

    @property
    def mass(self) -> float:
        """Mass rho A L (kg)."""
        return self.material.rho * self.A * self.L

    def M(self) -> np.ndarray:
        """Mass matrix (translational + rotary), shape (8 + n_internal,) * 2 (kg, kg m, kg m^2)."""
        rho, phi = self.material.rho, self.phi
        if self.element == "hierarchical":
            return (_gen.hierarchical_mass_translational(self.L, rho, self.A, phi)
                    + _gen.hierarchical_mass_rotary(self.L, rho, self.I, phi))
        return (_gen.timoshenko_mass_translational(self.L, rho, self.A, phi)
                + _gen.timoshenko_mass_rotary(self.L, rho, self.I, phi))

    def K(self) -> np.ndarray:
        """Stiffness matrix, shape (8 + n_internal,) * 2 (N/m, N, N m)."""
        if self.element == "hierarchical":
            return _gen.hierarchical_stiffness(self.L, self.material.E, self.I, self.phi)
        return _gen.timoshenko_stiffness(self.L, self.material.E, self.I, self.phi)

    def G(self) -> np.ndarray:
        """Gyroscopic matrix per unit spin speed, shape (8 + n_internal,) * 2 (kg m^2 per rad)."""
        if self.element == "hierarchical":
            return _gen.hierarchical_gyroscopic(self.L, self.material.rho, self.I, self.phi)
        return _gen.timoshenko_gyroscopic(self.L, self.material.rho, self.I, self.phi)

    def split(self, n: int, new_nodes: list[int]) -> list[ShaftElement]:
        """Split into ``n`` equal elements through ``new_nodes`` (length n - 1)."""
        chain = [self.left, *new_nodes, self.right]
        return [ShaftElement(chain[i], chain[i + 1], self.L / n, self.D_o, self.D_i, self.material, self.shear,
                             self.element) for i in range(n)]


@dataclass(frozen=True)
class Disk:
    """Rigid disk at a node.

    Parameters
    ----------
    node : int
    m : float
        Mass (kg).
    I_d : float
        Diametral moment of inertia (kg m^2).
    I_p : float
        Polar moment of inertia (kg m^2).
    name : str
    radius : float
        Outer (rim) radius (m), used by the rub-impact law; 0 if unknown.
    """

    node: int
    m: float
    I_d: float
    I_p: float
    name: str = ""
    radius: float = 0.0

    def __post_init__(self):
        if not isinstance(self.node, int) or isinstance(self.node, bool):
            raise ValueError(f"`node` must be an integer node number, got {self.node!r}")
        _positive("m", self.m, " (kg)")
        _non_negative("I_d", self.I_d, " (kg m^2)")
        _non_negative("I_p", self.I_p, " (kg m^2)")
        _non_negative("radius", self.radius, " (m)")

    def M(self) -> np.ndarray:
        """Mass matrix, shape (4, 4)."""
        return _gen.disk_mass(self.m, self.I_d)

    def G(self) -> np.ndarray:
        """Gyroscopic matrix per unit spin speed, shape (4, 4)."""
        return _gen.disk_gyroscopic(self.I_p)


@dataclass(frozen=True)
class _Support:
    k_xx: float = 0.0
    k_yy: float = 0.0
    k_xy: float = 0.0
    k_yx: float = 0.0
    c_xx: float = 0.0
    c_yy: float = 0.0
    c_xy: float = 0.0
    c_yx: float = 0.0
    name: str = ""

    def _validate(self):
        for c in ("k_xx", "k_yy", "c_xx", "c_yy"):
            _non_negative(c, getattr(self, c), " (N/m)" if c[0] == "k" else " (N s/m)")
        for c in ("k_xy", "k_yx", "c_xy", "c_yx"):
            _finite(c, getattr(self, c))

    @property
    def K(self) -> np.ndarray:
        """Translational stiffness [[k_xx, k_xy], [k_yx, k_yy]], shape (2, 2) (N/m)."""
        return np.array([[self.k_xx, self.k_xy], [self.k_yx, self.k_yy]])

    @property
    def C(self) -> np.ndarray:
        """Translational damping [[c_xx, c_xy], [c_yx, c_yy]], shape (2, 2) (N s/m)."""
        return np.array([[self.c_xx, self.c_xy], [self.c_yx, self.c_yy]])


@dataclass(frozen=True)
class Bearing(_Support):
    """Linear bearing from a node to ground (x and y only).

    Parameters
    ----------
    node : int
    k_xx, k_yy, k_xy, k_yx : float
        Stiffness coefficients (N/m); the force on the shaft is -K [x, y].
    c_xx, c_yy, c_xy, c_yx : float
        Damping coefficients (N s/m).
    name : str
    """

    node: int = field(default=-1, kw_only=True)

    def __post_init__(self):
        if not isinstance(self.node, int) or isinstance(self.node, bool) or self.node < 0:
            raise ValueError(f"`node` must be an integer node number, got {self.node!r}")
        self._validate()


@dataclass(frozen=True)
class IntershaftBearing(_Support):
    """Linear bearing between a node of one spool and a node of another.

    The force on ``node_a`` is -K (u_a - u_b) - C (u_a' - u_b'), on ``node_b`` its opposite.

    Parameters
    ----------
    node_a, node_b : int
    k_xx, k_yy, k_xy, k_yx : float
        Stiffness (N/m).
    c_xx, c_yy, c_xy, c_yx : float
        Damping (N s/m).
    name : str
    """

    node_a: int = field(default=-1, kw_only=True)
    node_b: int = field(default=-1, kw_only=True)

    def __post_init__(self):
        for name in ("node_a", "node_b"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 0:
                raise ValueError(f"`{name}` must be an integer node number, got {value!r}")
        if self.node_a == self.node_b:
            raise ValueError(f"`node_a` and `node_b` must differ, got {self.node_a} for both")
        self._validate()

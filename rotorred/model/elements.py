"""Model inputs: material, shaft element, rigid disk, bearing, inter-shaft bearing.

Each is a frozen dataclass validated at construction (:mod:`rotorred.checks`); a bad value
raises :class:`rotorred.checks.InputError` (a ``ValueError``) naming the attribute, the value and
what is allowed, e.g. ``D_i = 0.06: must be < D_o = 0.05 (m)``; a file loader prefixes the
attribute with the key path (``spool[0].elements[2].D_i``). Numbers are stored as ``float``,
node numbers as ``int``. Element matrices come from the generated module
:mod:`rotorred._generated.timoshenko` (``python -m derivations``).

DOF order at a node (:mod:`rotorred.model.dofs`): (x, y, theta_x, theta_y); z is the shaft axis.
A positive theta_y turns z towards x, a positive theta_x turns z towards -y; a spool spins about +z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rotorred import checks
from rotorred._generated.tapered import tapered_mass_rotary, tapered_mass_translational
from rotorred._generated.tapered import tapered_spin_acceleration, tapered_stiffness
from rotorred._generated import timoshenko as _gen
from rotorred._generated.internal_damping import hierarchical_spin_rotation, timoshenko_spin_rotation

SHEAR_METHODS = ("cowper", "hutchinson", "ross-hutchinson", "none")
FORMULATIONS = ("nelson", "hierarchical")


def _set(obj, name: str, value) -> None:
    """Store a checked (converted) value on a frozen dataclass."""
    object.__setattr__(obj, name, value)


#: largest Young's modulus accepted (Pa): a million times steel's, room for the "rigid shaft" idiom
#: (E = 1000 x steel) while keeping the stiffness matrix far inside double precision
E_MAX = 1e18
#: densities accepted (kg/m^3): far above osmium; down to 1e-9 for the "massless shaft" idiom (rho = 1e-6:
#: a shaft mass 1e-11 of a disk's), below which a shaft's mass is lost in the round-off of a disk's
RHO_RANGE = (1e-9, 1e6)


@dataclass(frozen=True)
class Material:
    """Isotropic linear-elastic material.

    Parameters
    ----------
    name : str
    E : float
        Young's modulus (Pa), 0 < E <= 1e18 (:data:`E_MAX`).
    rho : float
        Density (kg/m^3), 1e-9 <= rho <= 1e6 (:data:`RHO_RANGE`).
    nu : float, optional
        Poisson's ratio (-), -1 < nu < 0.5; default 0.3 when ``G`` is not given either.
    G : float, optional
        Shear modulus (Pa), in place of ``nu`` (textbooks give E, G and rho): then
        ``nu = E / (2 G) - 1``, which must lie in (-1, 0.5), i.e. E / 3 < G. Not with ``nu``.

    Notes
    -----
    The bounds on ``E`` and ``rho`` are far outside every engineering material (diamond:
    E = 1.2e12 Pa, and a "rigid" shaft modelled as 1000 x steel; osmium: rho = 22 600 kg/m^3;
    a "massless" shaft modelled with rho = 1e-6) and keep the element
    matrices inside double precision: ``E = 1e300`` overflows the stiffness and ``rho = 1e-300``
    makes the mass matrix singular, which otherwise surfaced as an eigen-solver error far from
    the key that caused it.
    """

    name: str
    E: float
    rho: float
    nu: float | None = None
    G: float | None = None

    def __post_init__(self):
        _set(self, "name", checks.string("name", self.name))
        _set(self, "E", checks.number("E", self.E, "Pa", gt=0.0, le=E_MAX))
        _set(self, "rho", checks.number("rho", self.rho, "kg/m^3", ge=RHO_RANGE[0], le=RHO_RANGE[1]))
        if self.G is None:
            _set(self, "nu", checks.number("nu", 0.3 if self.nu is None else self.nu, "-", gt=-1.0, lt=0.5))
            return
        if self.nu is not None:
            checks.fail("G", self.G, "must not be given with nu (G = E / (2 (1 + nu)) fixes one by the other)", "Pa")
        G = checks.number("G", self.G, "Pa", gt=0.0)
        if G <= self.E / 3.0:
            checks.fail("G", G, f"must be > E / 3 = {self.E / 3.0:.6g} so that nu = E / (2 G) - 1 < 0.5", "Pa")
        _set(self, "G", G)
        _set(self, "nu", self.E / (2.0 * G) - 1.0)

    @property
    def G_s(self) -> float:
        """Shear modulus (Pa): ``G`` as given, else E / (2 (1 + nu))."""
        return self.G if self.G is not None else self.E / (2.0 * (1.0 + self.nu))


def shear_coefficient(D_o: float, D_i: float, nu: float, method: str = "cowper") -> float:
    """Timoshenko shear coefficient kappa of a hollow circular section.

    Parameters
    ----------
    D_o, D_i : float
        Outer and inner diameter (m), 0 <= D_i < D_o.
    nu : float
        Poisson's ratio (-).
    method : {"cowper", "hutchinson", "ross-hutchinson"}
        ``"cowper"``: Cowper (1966), J. Appl. Mech. 33, Table 1, hollow circle,
        kappa = 6 (1+nu)(1+m^2)^2 / ((7+6nu)(1+m^2)^2 + (20+12nu) m^2), m = D_i/D_o.
        ``"hutchinson"``: Hutchinson (2001), J. Appl. Mech. 68, Eq. (52), hollow circle
        (a = outer, b = inner radius),
        kappa = 6 (a^2+b^2)^2 (1+nu)^2 / (7a^4 + 34a^2b^2 + 7b^4
        + nu (12a^4 + 48a^2b^2 + 12b^4) + nu^2 (4a^4 + 16a^2b^2 + 4b^4)).
        The (1+nu)^2 factor is part of the published formula.
        ``"ross-hutchinson"``: ROSS's line for Hutchinson's coefficient (``ShaftElement(shear_method_calc=
        "hutchinson")``), which has (1+nu) where the published formula has (1+nu)^2: the published value / (1+nu),
        to reproduce a ROSS rotor (docs/model.md §20).

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
    if method == "ross-hutchinson":
        return shear_coefficient(D_o, D_i, nu, "hutchinson") / (1 + nu)
    checks.choice("method", method, ("cowper", "hutchinson", "ross-hutchinson"))


@dataclass(frozen=True)
class ShaftElement:
    """Hollow circular Timoshenko shaft element between two nodes of one spool, uniform or tapered.

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
    shear : {"cowper", "hutchinson", "ross-hutchinson", "none"}
        Shear coefficient formula (:func:`shear_coefficient`); ``"none"`` gives the Euler-Bernoulli element (phi = 0)
        with rotary inertia (Rayleigh beam).
    element : {"nelson", "hierarchical"}
        ``"nelson"`` (default): interdependent interpolation (Nelson 1980), 4 DOFs per node,
        exact in statics; its constant shear strain makes eigenvalues converge as h^2 with a
        small constant. ``"hierarchical"``: cubic displacement and quadratic rotation with 6
        internal bubble DOFs per element (``n_internal``); eigenvalues converge as h^4. See
        docs/model.md, "Shaft element".
    rotary_inertia : bool
        Rotary inertia of the cross-section (default True). False leaves out the rotary mass and
        with it the shaft's own gyroscopic matrix (both are rho I): with ``shear = "none"`` this
        is the Euler-Bernoulli beam of the textbooks (no shear, no rotary inertia).
    D_o_right, D_i_right : float, optional
        Diameters at the right node (m) of a tapered element, default ``D_o`` and ``D_i``: the
        diameters vary linearly from left to right and the element is the conical one of
        derivations/tapered.py (``element = "nelson"`` only). ``D_o``, ``D_i`` are then the left ones.
    internal_damping_beta : float, optional
        Internal (rotating) viscous damping (s): the damping ``beta K`` acting in the frame that turns with the
        shaft (docs/model.md §19), >= 0. None (default): its spool's
        (:attr:`rotorred.model.rotor.Spool.internal_damping_beta`).
    internal_loss_factor : float, optional
        Internal hysteretic damping: loss factor eta (-), >= 0, as the viscous ``beta = eta / |omega|`` at the whirl
        frequency omega (docs/model.md §19). None (default): its spool's.
    """

    left: int
    right: int
    L: float
    D_o: float
    D_i: float
    material: Material
    shear: str = "cowper"
    element: str = "nelson"
    rotary_inertia: bool = True
    D_o_right: float | None = None
    D_i_right: float | None = None
    internal_damping_beta: float | None = None
    internal_loss_factor: float | None = None

    def __post_init__(self):
        _set(self, "left", checks.integer("left", self.left, ge=0))
        for key, unit in (("internal_damping_beta", "s"), ("internal_loss_factor", "-")):
            if getattr(self, key) is not None:
                _set(self, key, checks.non_negative(key, getattr(self, key), unit))
        if not isinstance(self.rotary_inertia, (bool, np.bool_)):
            checks.fail("rotary_inertia", self.rotary_inertia, "must be true or false")
        _set(self, "right", checks.integer("right", self.right, ge=0))
        if self.left == self.right:
            checks.fail("right", self.right, f"must differ from left = {self.left}")
        _set(self, "L", checks.positive("L", self.L, "m"))
        _set(self, "D_o", checks.positive("D_o", self.D_o, "m"))
        _set(self, "D_i", checks.non_negative("D_i", self.D_i, "m"))
        if self.D_i >= self.D_o:
            checks.fail("D_i", self.D_i, f"must be < D_o = {self.D_o:g}", "m")
        if not isinstance(self.material, Material):
            checks.fail("material", self.material, "must be a Material")
        checks.choice("shear", self.shear, SHEAR_METHODS)
        checks.choice("element", self.element, FORMULATIONS)
        if self.element == "hierarchical" and self.shear == "none":
            checks.fail("element", self.element, "must be 'nelson' with shear = 'none' (an Euler-Bernoulli element): "
                        "the hierarchical element needs shear = 'cowper' or 'hutchinson'")
        _set(self, "D_o_right", self.D_o if self.D_o_right is None else checks.positive("D_o_right", self.D_o_right, "m"))
        _set(self, "D_i_right", self.D_i if self.D_i_right is None else
             checks.non_negative("D_i_right", self.D_i_right, "m"))
        if self.D_i_right >= self.D_o_right:
            checks.fail("D_i_right", self.D_i_right, f"must be < D_o_right = {self.D_o_right:g}", "m")
        if self.tapered and self.element != "nelson":
            checks.fail("element", self.element, "must be 'nelson' for a tapered element (D_o_right, D_i_right given)")

    @property
    def tapered(self) -> bool:
        """Whether the diameters differ between the nodes."""
        return self.D_o_right != self.D_o or self.D_i_right != self.D_i

    @property
    def _mid(self) -> tuple[float, float]:
        """Outer and inner diameter at mid-length (m): the section of ``A``, ``I``, ``kappa`` and ``phi``."""
        return 0.5 * (self.D_o + self.D_o_right), 0.5 * (self.D_i + self.D_i_right)

    @property
    def n_internal(self) -> int:
        """Number of internal (bubble) DOFs: 0 for ``"nelson"``, 6 for ``"hierarchical"``."""
        return 6 if self.element == "hierarchical" else 0

    @property
    def A(self) -> float:
        """Cross-section area (m^2) (at mid-length for a tapered element)."""
        D_o, D_i = self._mid
        return math.pi * (D_o**2 - D_i**2) / 4.0

    @property
    def I(self) -> float:  # noqa: E743 - textbook symbol
        """Diametral second moment of area (m^4) (at mid-length for a tapered element); the polar one is 2 I."""
        D_o, D_i = self._mid
        return math.pi * (D_o**4 - D_i**4) / 64.0

    @property
    def kappa(self) -> float:
        """Shear coefficient (-) (of the mid-length section for a tapered element); inf for ``shear="none"``."""
        if self.shear == "none":
            return math.inf
        return shear_coefficient(*self._mid, self.material.nu, self.shear)

    @property
    def phi(self) -> float:
        """Shear parameter 12 E I / (kappa G A L^2) (-)."""
        if self.shear == "none":
            return 0.0
        mat = self.material
        return 12.0 * mat.E * self.I / (self.kappa * mat.G_s * self.A * self.L**2)

    @property
    def mass(self) -> float:
        """Mass rho int A dz (kg)."""
        A0, A1, A2 = self.taper()[0]
        return self.material.rho * self.L * (A0 + A1 / 2 + A2 / 3)

    def taper(self) -> tuple[tuple[float, float, float], tuple[float, float, float, float, float]]:
        """The section along the element, ``xi = z / L``: (A0, A1, A2) of A(xi) = sum A_k xi^k (m^2) and (I0, ..., I4)
        of I(xi) = sum I_k xi^k (m^4), from the linear diameters ``d(xi) = d_left + (d_right - d_left) xi``."""
        a, b = self.D_o, self.D_o_right - self.D_o
        c, e = self.D_i, self.D_i_right - self.D_i
        A = tuple(math.pi / 4 * math.comb(2, k) * (a ** (2 - k) * b**k - c ** (2 - k) * e**k) for k in range(3))
        I = tuple(math.pi / 64 * math.comb(4, k) * (a ** (4 - k) * b**k - c ** (4 - k) * e**k) for k in range(5))  # noqa: E741
        return A, I

    def _tapered_rotary(self) -> tuple[float, ...]:
        """I(xi)'s coefficients as the rotary inertia sees them (zeros without rotary inertia)."""
        return self.taper()[1] if self.rotary_inertia else (0.0,) * 5

    def M(self) -> np.ndarray:
        """Mass matrix (translational + rotary), shape (8 + n_internal,) * 2 (kg, kg m, kg m^2)."""
        rho, phi = self.material.rho, self.phi
        if self.tapered:
            return (tapered_mass_translational(self.L, rho, *self.taper()[0], phi)
                    + tapered_mass_rotary(self.L, rho, *self._tapered_rotary(), phi))
        I_r = self.I if self.rotary_inertia else 0.0  # no rotary mass: the generated term at I = 0
        if self.element == "hierarchical":
            return (_gen.hierarchical_mass_translational(self.L, rho, self.A, phi)
                    + _gen.hierarchical_mass_rotary(self.L, rho, I_r, phi))
        return (_gen.timoshenko_mass_translational(self.L, rho, self.A, phi)
                + _gen.timoshenko_mass_rotary(self.L, rho, I_r, phi))

    def K(self) -> np.ndarray:
        """Stiffness matrix, shape (8 + n_internal,) * 2 (N/m, N, N m)."""
        if self.tapered:  # Euler-Bernoulli (phi = 0): no shear strain, kappa G does not enter
            kG = 0.0 if self.shear == "none" else self.kappa * self.material.G_s
            A, I = self.taper()  # noqa: E741
            return tapered_stiffness(self.L, self.material.E, *I, kG, *A, self.phi)
        if self.element == "hierarchical":
            return _gen.hierarchical_stiffness(self.L, self.material.E, self.I, self.phi)
        return _gen.timoshenko_stiffness(self.L, self.material.E, self.I, self.phi)

    def G(self) -> np.ndarray:
        """Gyroscopic matrix per unit spin speed, shape (8 + n_internal,) * 2 (kg m^2 per rad)."""
        if self.tapered:
            A_g = self.K_G()
            return A_g - A_g.T
        I_r = self.I if self.rotary_inertia else 0.0  # the gyroscopic matrix is rotary inertia spun
        if self.element == "hierarchical":
            return _gen.hierarchical_gyroscopic(self.L, self.material.rho, I_r, self.phi)
        return _gen.timoshenko_gyroscopic(self.L, self.material.rho, I_r, self.phi)

    def K_G(self) -> np.ndarray:
        """Spin-acceleration matrix per unit angular acceleration, shape (8 + n_internal,) * 2 (kg m^2 per rad):
        the ``A`` of ``G = A - A^T`` (docs/model.md, Eq. R2)."""
        if self.tapered:
            return tapered_spin_acceleration(self.L, self.material.rho, *self._tapered_rotary(), self.phi)
        I_r = self.I if self.rotary_inertia else 0.0
        if self.element == "hierarchical":
            return _gen.hierarchical_spin_acceleration(self.L, self.material.rho, I_r, self.phi)
        return _gen.timoshenko_spin_acceleration(self.L, self.material.rho, I_r, self.phi)

    def spin_rotation(self) -> np.ndarray:
        """Rotation generator ``J`` of the element's DOFs, ``q = exp(Omega t J) q_r`` from the rotating frame,
        shape (8 + n_internal,) * 2 (-): the rotating damping ``beta K`` is the circulatory stiffness
        ``-Omega beta K J`` in the fixed frame (derivations/internal_damping.py)."""
        return hierarchical_spin_rotation() if self.element == "hierarchical" else timoshenko_spin_rotation()

    def split(self, n: int, new_nodes: list[int]) -> list[ShaftElement]:
        """Split into ``n`` equal elements through ``new_nodes`` (length n - 1); a taper is split along its line.

        Parameters
        ----------
        n : int
            Number of elements, >= 1; each has length ``L / n`` (m).
        new_nodes : list of int, length n - 1
            Numbers of the inner nodes, from ``left`` to ``right``.

        Returns
        -------
        list of ShaftElement, length n
            From ``left`` to ``right``; a tapered element's diameters (m) follow its linear taper.
        """
        chain = [self.left, *new_nodes, self.right]
        return [ShaftElement(chain[i], chain[i + 1], self.L / n, along(self.D_o, self.D_o_right, i / n),
                             along(self.D_i, self.D_i_right, i / n), self.material, self.shear, self.element,
                             self.rotary_inertia, along(self.D_o, self.D_o_right, (i + 1) / n),
                             along(self.D_i, self.D_i_right, (i + 1) / n), self.internal_damping_beta,
                             self.internal_loss_factor) for i in range(n)]


def along(left: float, right: float, xi: float) -> float:
    """The diameter at ``xi`` (0..1) of a linear taper from ``left`` to ``right`` (m), the ends exactly."""
    if xi == 0.0:
        return left
    if xi == 1.0:
        return right
    return left + (right - left) * xi


@dataclass(frozen=True)
class Disk:
    """Rigid disk at a node.

    Parameters
    ----------
    node : int
        The shaft node the disk sits at.
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
        _set(self, "node", checks.integer("node", self.node))
        _set(self, "m", checks.positive("m", self.m, "kg"))
        _set(self, "I_d", checks.non_negative("I_d", self.I_d, "kg m^2"))
        _set(self, "I_p", checks.non_negative("I_p", self.I_p, "kg m^2"))
        _set(self, "name", checks.string("name", self.name))
        _set(self, "radius", checks.non_negative("radius", self.radius, "m"))

    def M(self) -> np.ndarray:
        """Mass matrix, shape (4, 4)."""
        return _gen.disk_mass(self.m, self.I_d)

    def G(self) -> np.ndarray:
        """Gyroscopic matrix per unit spin speed, shape (4, 4)."""
        return _gen.disk_gyroscopic(self.I_p)

    def K_G(self) -> np.ndarray:
        """Spin-acceleration matrix per unit angular acceleration, shape (4, 4): ``I_p`` at (theta_x, theta_y)."""
        return _gen.disk_spin_acceleration(self.I_p)


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
    k_txtx: float = 0.0
    k_tyty: float = 0.0
    k_txty: float = 0.0
    k_tytx: float = 0.0
    c_txtx: float = 0.0
    c_tyty: float = 0.0
    c_txty: float = 0.0
    c_tytx: float = 0.0

    def _validate(self):
        for c in COEFFICIENTS:
            _set(self, c, checks.number(c, getattr(self, c), coefficient_unit(c), ge=_least(c)))
        _set(self, "name", checks.string("name", self.name))

    @property
    def K(self) -> np.ndarray:
        """Translational stiffness [[k_xx, k_xy], [k_yx, k_yy]], shape (2, 2) (N/m)."""
        return np.array([[self.k_xx, self.k_xy], [self.k_yx, self.k_yy]])

    @property
    def C(self) -> np.ndarray:
        """Translational damping [[c_xx, c_xy], [c_yx, c_yy]], shape (2, 2) (N s/m)."""
        return np.array([[self.c_xx, self.c_xy], [self.c_yx, self.c_yy]])

    @property
    def K_tilt(self) -> np.ndarray:
        """Tilt stiffness [[k_txtx, k_txty], [k_tytx, k_tyty]] on (theta_x, theta_y), shape (2, 2) (N m/rad)."""
        return np.array([[self.k_txtx, self.k_txty], [self.k_tytx, self.k_tyty]])

    @property
    def C_tilt(self) -> np.ndarray:
        """Tilt damping [[c_txtx, c_txty], [c_tytx, c_tyty]] on (theta_x, theta_y), shape (2, 2) (N m s/rad)."""
        return np.array([[self.c_txtx, self.c_txty], [self.c_tytx, self.c_tyty]])

    @property
    def tilts(self) -> bool:
        """Whether any tilt coefficient is non-zero."""
        return any(getattr(self, c) != 0.0 for c in TILT_COEFFICIENTS)

    def block(self, matrix: str) -> np.ndarray:
        """The support's ``matrix`` (``"K"``: stiffness, ``"C"``: damping) on a node's (x, y, theta_x, theta_y), shape
        (4, 4): the translational 2 x 2 and the tilt 2 x 2 on the diagonal (no translation-tilt coupling)."""
        out = np.zeros((4, 4))
        out[:2, :2] = getattr(self, matrix)
        out[2:, 2:] = getattr(self, f"{matrix}_tilt")
        return out


@dataclass(frozen=True)
class Bearing(_Support):
    """Linear bearing from a node to ground, or to a pedestal (x and y only).

    Parameters
    ----------
    node : int
        The shaft (or pedestal) node the bearing holds.
    k_xx, k_yy, k_xy, k_yx : float
        Stiffness coefficients (N/m), any sign (a seal's direct stiffness may be negative); the force on the shaft is
        -K [x, y] (-K [x - x_link, y - y_link] with a link).
    c_xx, c_yy, c_xy, c_yx : float
        Damping coefficients (N s/m); the direct ones (c_xx, c_yy) >= 0.
    name : str
    k_txtx, k_tyty, k_txty, k_tytx : float
        Tilt stiffness (N m/rad), any sign: the moment on the shaft is -K_tilt [theta_x, theta_y] (docs/model.md §20;
        with a link too, as a pedestal does not tilt). Not at a pedestal node (it has no rotations).
    c_txtx, c_tyty, c_txty, c_tytx : float
        Tilt damping (N m s/rad); the direct ones >= 0.
    link : int or None
        The pedestal node (:class:`Pedestal`) the bearing joins ``node`` to; None: ground.
    """

    node: int = field(default=-1, kw_only=True)
    link: int | None = field(default=None, kw_only=True)

    def __post_init__(self):
        _set(self, "node", checks.integer("node", self.node, ge=0))
        _check_link(self)
        self._validate()


def _check_link(bearing) -> None:
    if bearing.link is not None:
        _set(bearing, "link", checks.integer("link", bearing.link, ge=0))
        if bearing.link == bearing.node:
            checks.fail("link", bearing.link, f"must differ from node = {bearing.node}")


@dataclass(frozen=True)
class Pedestal:
    """An off-shaft node with mass and x, y only: a bearing housing on its own springs, a pedestal, a casing point.

    It is held to ground by the bearings given at its node and joined to the shaft by the bearings that name it as
    their ``link``.

    Parameters
    ----------
    node : int
        A node number of no spool.
    m : float
        Mass (kg), in x and in y.
    name : str
    """

    node: int
    m: float
    name: str = ""

    def __post_init__(self):
        _set(self, "node", checks.integer("node", self.node, ge=0))
        _set(self, "m", checks.positive("m", self.m, "kg"))
        _set(self, "name", checks.string("name", self.name))

    def M(self) -> np.ndarray:
        """Mass matrix on (x, y), shape (2, 2) (kg)."""
        return self.m * np.eye(2)


#: the directions each kind of :class:`Support` fixes
SUPPORT_KINDS = {"pinned": ("x", "y"), "clamped": ("x", "y", "theta_x", "theta_y")}


@dataclass(frozen=True)
class Support:
    """A rigid support of a node: ``"pinned"`` fixes its x and y (it may still tilt), ``"clamped"`` also
    theta_x and theta_y. The fixed DOFs are removed from the model (exact), not held by a stiff spring.

    Parameters
    ----------
    node : int
        The node supported.
    kind : str
        ``"pinned"`` or ``"clamped"``.
    name : str
    """

    node: int
    kind: str = "pinned"
    name: str = ""

    def __post_init__(self):
        _set(self, "node", checks.integer("node", self.node, ge=0))
        _set(self, "kind", checks.choice("kind", self.kind, tuple(SUPPORT_KINDS)))
        _set(self, "name", checks.string("name", self.name))

    @property
    def fixed(self) -> tuple[str, ...]:
        """The directions the support fixes."""
        return SUPPORT_KINDS[self.kind]


#: what a :class:`BearingTable` does outside its speeds
EXTRAPOLATIONS = ("hold", "linear")
#: how a :class:`BearingTable` interpolates between its speeds
INTERPOLATIONS = ("linear", "pchip")

#: the translational coefficients of a support, in the order of :class:`_Support`'s fields
TRANSLATIONAL_COEFFICIENTS = ("k_xx", "k_yy", "k_xy", "k_yx", "c_xx", "c_yy", "c_xy", "c_yx")
#: the tilt coefficients of a support (on theta_x, theta_y; docs/model.md §20)
TILT_COEFFICIENTS = ("k_txtx", "k_tyty", "k_txty", "k_tytx", "c_txtx", "c_tyty", "c_txty", "c_tytx")
#: every coefficient of a support
COEFFICIENTS = TRANSLATIONAL_COEFFICIENTS + TILT_COEFFICIENTS
#: the coefficients that must be >= 0: a passive support's direct damping. Direct stiffness may be negative (annular
#: and labyrinth seals have it: Childs 1993, Turbomachinery Rotordynamics, ch. 4), cross-coupled terms have any sign.
DIRECT_DAMPING = ("c_xx", "c_yy", "c_txtx", "c_tyty")


def _least(c: str) -> float | None:
    """The lower bound of coefficient ``c``: 0 for direct damping, none for the others."""
    return 0.0 if c in DIRECT_DAMPING else None


def coefficient_unit(c: str) -> str:
    """The SI unit of support coefficient ``c``: N/m, N s/m; N m/rad, N m s/rad for the tilt terms."""
    tilt = c in TILT_COEFFICIENTS
    return {("k", False): "N/m", ("c", False): "N s/m", ("k", True): "N m/rad", ("c", True): "N m s/rad"}[c[0], tilt]


class _TableRules:
    """What every bearing table does with its columns (:class:`BearingTable`, :class:`IntershaftBearingTable`): check
    them against its speeds, interpolate and extrapolate them (docs/model.md §10). A class using it is a frozen
    dataclass with ``speeds``, the :data:`COEFFICIENTS` columns, ``interpolation`` and ``extrapolate``."""

    def _check_table(self) -> None:
        _set(self, "extrapolate", checks.choice("extrapolate", self.extrapolate, EXTRAPOLATIONS))
        _set(self, "interpolation", checks.choice("interpolation", self.interpolation, INTERPOLATIONS))
        speeds = checks.vector("speeds", self.speeds, "rad/s", min_len=2, ge=0.0, increasing=True)
        _set(self, "speeds", tuple(float(v) for v in speeds))
        for c in COEFFICIENTS:
            unit, ge, value = coefficient_unit(c), _least(c), getattr(self, c)
            if np.ndim(value) == 0:
                value = [checks.number(c, value, unit, ge=ge)] * len(speeds)
            column = checks.vector(c, value, unit, min_len=len(speeds), max_len=len(speeds), ge=ge)
            _set(self, c, tuple(float(v) for v in column))
        _set(self, "name", checks.string("name", self.name))
        if self.interpolation == "pchip" and len(speeds) > 2:
            _set(self, "_curves", {c: _pchip(speeds, getattr(self, c)) for c in COEFFICIENTS})

    def _coefficients_at(self, Omega: float, where: str) -> dict[str, float]:
        """Every coefficient at speed ``Omega`` (rad/s); a direct damping extrapolated below 0 is refused, naming
        the bearing by ``where``."""
        Omega = checks.non_negative("Omega", Omega, "rad/s")
        values = {c: self._value(c, Omega) for c in COEFFICIENTS}
        for c in DIRECT_DAMPING:
            if values[c] < 0.0:
                checks.fail("extrapolate", self.extrapolate, f"gives {c} = {values[c]:.6g} at {Omega:.6g} rad/s for "
                            f"the bearing at {where}, below 0 (its table covers {self.speeds[0]:.6g}-"
                            f"{self.speeds[-1]:.6g} rad/s); extend the table or hold its ends (extrapolate = 'hold')")
        return values

    def _value(self, c: str, Omega: float) -> float:
        W, v = self.speeds, getattr(self, c)
        curves = getattr(self, "_curves", None)
        end = 0 if Omega < W[0] else -1  # the table's end on Omega's side, where it lies outside the table
        if curves is None:  # straight segments
            if self.extrapolate == "linear" and not self.covers(Omega):
                i = 0 if end == 0 else len(W) - 2  # the end segment on that side
                return float(v[i] + (v[i + 1] - v[i]) * (Omega - W[i]) / (W[i + 1] - W[i]))
            return float(np.interp(Omega, W, v))
        value, slope = curves[c]
        if self.covers(Omega):
            return float(value(Omega))
        tangent = slope[end] if self.extrapolate == "linear" else 0.0
        return float(v[end] + tangent * (Omega - W[end]))

    def covers(self, Omega: float) -> bool:
        """Whether ``Omega`` (rad/s) lies within the table's speeds (outside, :attr:`extrapolate` applies).

        Parameters
        ----------
        Omega : float
            Spool speed (rad/s).
        """
        return self.speeds[0] <= Omega <= self.speeds[-1]


#: what the axis of a :class:`BearingTable` is: the spool's speed, or the whirl frequency of a table made against it
#: (ROSS's ``frequency``), evaluated at frequency = spool speed (docs/model.md §20)
TABLE_AXES = ("speed", "frequency")


@dataclass(frozen=True)
class BearingTable(_TableRules):
    """Bearing from a node to ground whose coefficients are tabulated against the speed of the node's spool
    (fluid-film bearings, seals).

    Between the table's speeds each coefficient is interpolated linearly (``interpolation = "linear"``,
    the default) or by the shape-preserving piecewise cubic Hermite interpolant (``"pchip"``, Fritsch &
    Carlson; ROSS 3's default): neither overshoots the tabulated values. Outside them it keeps the value
    of the nearest end (``extrapolate = "hold"``, the default: docs/model.md §10), or follows the
    interpolant's tangent line at that end (``"linear"``, what ROSS does; a direct damping coefficient
    extrapolated below zero is refused). :meth:`at` gives the :class:`Bearing` at one speed.

    Parameters
    ----------
    node : int
        The shaft (or pedestal) node the bearing holds.
    speeds : sequence of float, shape (p,)
        Spool speeds of the table (rad/s), >= 0 and strictly increasing, at least 2.
    k_xx, k_yy, k_xy, k_yx : float or sequence of float, shape (p,)
        Stiffness (N/m) at each speed, any sign (a seal's direct stiffness may be negative); a single number holds
        at every speed; left out: 0.
    c_xx, c_yy, c_xy, c_yx : float or sequence of float, shape (p,)
        Damping (N s/m), the same way; the direct terms >= 0.
    name : str
    link : int or None
        The pedestal node the bearing joins ``node`` to; None: ground.
    extrapolate : {"hold", "linear"}
        Outside the table's speeds: the end values held, or the interpolant's tangent lines at the ends (the end
        segments with linear interpolation).
    interpolation : {"linear", "pchip"}
        Between the table's speeds: straight segments, or scipy's ``PchipInterpolator`` (C1, monotone between
        monotone data; with 2 speeds it is the straight line).
    k_txtx, k_tyty, k_txty, k_tytx, c_txtx, c_tyty, c_txty, c_tytx : float or sequence of float, shape (p,)
        Tilt stiffness (N m/rad) and damping (N m s/rad), as :class:`Bearing`'s, the same way.
    axis : {"speed", "frequency"}
        What the table's ``speeds`` were computed against: the spool speed, or the whirl (excitation) frequency of a
        synchronous analysis (ROSS's ``frequency`` tables). Both are evaluated at the spool's speed, which a
        ``"frequency"`` table takes as its frequency (docs/model.md §20); the axis is kept for what a file writes back.
    """

    node: int
    speeds: tuple[float, ...]
    k_xx: tuple[float, ...] | float = 0.0
    k_yy: tuple[float, ...] | float = 0.0
    k_xy: tuple[float, ...] | float = 0.0
    k_yx: tuple[float, ...] | float = 0.0
    c_xx: tuple[float, ...] | float = 0.0
    c_yy: tuple[float, ...] | float = 0.0
    c_xy: tuple[float, ...] | float = 0.0
    c_yx: tuple[float, ...] | float = 0.0
    name: str = ""
    link: int | None = None
    extrapolate: str = "hold"
    interpolation: str = "linear"
    k_txtx: tuple[float, ...] | float = 0.0
    k_tyty: tuple[float, ...] | float = 0.0
    k_txty: tuple[float, ...] | float = 0.0
    k_tytx: tuple[float, ...] | float = 0.0
    c_txtx: tuple[float, ...] | float = 0.0
    c_tyty: tuple[float, ...] | float = 0.0
    c_txty: tuple[float, ...] | float = 0.0
    c_tytx: tuple[float, ...] | float = 0.0
    axis: str = "speed"

    def __post_init__(self):
        _set(self, "node", checks.integer("node", self.node, ge=0))
        _check_link(self)
        _set(self, "axis", checks.choice("axis", self.axis, TABLE_AXES))
        self._check_table()

    @property
    def tilts(self) -> bool:
        """Whether any tilt coefficient is non-zero at a tabulated speed."""
        return any(v != 0.0 for c in TILT_COEFFICIENTS for v in getattr(self, c))

    def at(self, Omega: float) -> Bearing:
        """The bearing at spool speed ``Omega`` (rad/s): each coefficient interpolated in speed (:attr:`interpolation`);
        outside the table held at its ends or extrapolated along the interpolant's end tangents (:attr:`extrapolate`).

        Parameters
        ----------
        Omega : float
            Speed of the bearing's spool (rad/s), >= 0.

        Returns
        -------
        Bearing
            Stiffness (N/m) and damping (N s/m) coefficients at ``Omega`` (docs/model.md §10).

        Raises
        ------
        InputError
            If ``Omega`` < 0, or linear extrapolation gives a direct damping coefficient below 0.
        """
        return Bearing(node=self.node, name=self.name, link=self.link,
                       **self._coefficients_at(Omega, f"node {self.node}"))


def _pchip(speeds: np.ndarray, values: tuple[float, ...]):
    """The shape-preserving cubic through ``(speeds, values)`` and its slopes at the two ends."""
    from scipy.interpolate import PchipInterpolator  # 0.2 s to import (scipy.special, optimize, spatial): when used

    curve = PchipInterpolator(speeds, values, extrapolate=False)
    d = curve.derivative()
    return curve, (float(d(speeds[0])), float(d(speeds[-1])))


@dataclass(frozen=True)
class IntershaftBearing(_Support):
    """Linear bearing between a node of one spool and a node of another.

    The force on ``node_a`` is -K (u_a - u_b) - C (u_a' - u_b'), on ``node_b`` its opposite.

    Parameters
    ----------
    node_a, node_b : int
        The nodes joined, on two different spools.
    k_xx, k_yy, k_xy, k_yx : float
        Stiffness (N/m).
    c_xx, c_yy, c_xy, c_yx : float
        Damping (N s/m).
    name : str
    k_txtx, k_tyty, k_txty, k_tytx, c_txtx, c_tyty, c_txty, c_tytx : float
        Tilt stiffness (N m/rad) and damping (N m s/rad) on the relative tilt (theta_a - theta_b), as
        :class:`Bearing`'s.
    """

    node_a: int = field(default=-1, kw_only=True)
    node_b: int = field(default=-1, kw_only=True)

    def __post_init__(self):
        _check_nodes_ab(self)
        self._validate()


def _check_nodes_ab(bearing) -> None:
    _set(bearing, "node_a", checks.integer("node_a", bearing.node_a, ge=0))
    _set(bearing, "node_b", checks.integer("node_b", bearing.node_b, ge=0))
    if bearing.node_a == bearing.node_b:
        checks.fail("node_b", bearing.node_b, f"must differ from node_a = {bearing.node_a}")


@dataclass(frozen=True)
class IntershaftBearingTable(_TableRules):
    """Inter-shaft bearing whose coefficients are tabulated against the speed of one named spool (docs/model.md §20).

    The force on ``node_a`` is -K (u_a - u_b) - C (u_a' - u_b') with K, C at that spool's speed, on ``node_b`` its
    opposite; interpolated and extrapolated as a :class:`BearingTable`. :meth:`at` gives the
    :class:`IntershaftBearing` at one speed.

    Parameters
    ----------
    node_a, node_b : int
        The nodes joined, on two different spools.
    speeds : sequence of float, shape (p,)
        Speeds of spool ``speed_of`` (rad/s), >= 0 and strictly increasing, at least 2.
    k_xx, k_yy, k_xy, k_yx, c_xx, c_yy, c_xy, c_yx : float or sequence of float, shape (p,)
        Stiffness (N/m) and damping (N s/m) at each speed (a number: at every speed); the direct damping >= 0.
    name : str
    speed_of : str or None
        The spool whose speed the table follows; None: the spool of ``node_a`` (the rotor checks the name).
    extrapolate : {"hold", "linear"}
    interpolation : {"linear", "pchip"}
    k_txtx, k_tyty, k_txty, k_tytx, c_txtx, c_tyty, c_txty, c_tytx : float or sequence of float, shape (p,)
        Tilt stiffness (N m/rad) and damping (N m s/rad) on the relative tilt, the same way.
    """

    node_a: int
    node_b: int
    speeds: tuple[float, ...]
    k_xx: tuple[float, ...] | float = 0.0
    k_yy: tuple[float, ...] | float = 0.0
    k_xy: tuple[float, ...] | float = 0.0
    k_yx: tuple[float, ...] | float = 0.0
    c_xx: tuple[float, ...] | float = 0.0
    c_yy: tuple[float, ...] | float = 0.0
    c_xy: tuple[float, ...] | float = 0.0
    c_yx: tuple[float, ...] | float = 0.0
    name: str = ""
    speed_of: str | None = None
    extrapolate: str = "hold"
    interpolation: str = "linear"
    k_txtx: tuple[float, ...] | float = 0.0
    k_tyty: tuple[float, ...] | float = 0.0
    k_txty: tuple[float, ...] | float = 0.0
    k_tytx: tuple[float, ...] | float = 0.0
    c_txtx: tuple[float, ...] | float = 0.0
    c_tyty: tuple[float, ...] | float = 0.0
    c_txty: tuple[float, ...] | float = 0.0
    c_tytx: tuple[float, ...] | float = 0.0

    def __post_init__(self):
        _check_nodes_ab(self)
        if self.speed_of is not None:
            _set(self, "speed_of", checks.string("speed_of", self.speed_of, empty=False))
        self._check_table()

    @property
    def node(self) -> int:
        """``node_a``: the node that names the bearing in messages."""
        return self.node_a

    def at(self, Omega: float) -> IntershaftBearing:
        """The inter-shaft bearing at speed ``Omega`` (rad/s) of spool :attr:`speed_of`, as :meth:`BearingTable.at`.

        Parameters
        ----------
        Omega : float
            Speed of spool ``speed_of`` (rad/s), >= 0.

        Returns
        -------
        IntershaftBearing
            Stiffness (N/m, N m/rad) and damping (N s/m, N m s/rad) at ``Omega``.
        """
        return IntershaftBearing(node_a=self.node_a, node_b=self.node_b, name=self.name,
                                 **self._coefficients_at(Omega, f"nodes {self.node_a}-{self.node_b}"))

"""Benchmark models of the forced-response engine: Jenkins-damped chains, defined once.

Each case is plain data (matrices, Jenkins links, excitation, harmonics, band), so the
same definition builds a :class:`~harmonic_balance.model.Model`, the ``.npz`` /
``.toml`` files of ``damper frf``, and the input of a peer code (``damper.bench``).

Symbols (SI units): M, K, C (n, n) mass [kg], stiffness [N/m] and viscous damping
[N s/m]; f (n,) amplitude [N] of the excitation f cos(omega t); a Jenkins link joins
DOF a to DOF b (or the ground) through a spring k [N/m] in series with a slider of
slip force f_s [N], acting on u = x_a - x_b; H the highest harmonic (0..H kept);
omega [rad/s].

Cases
-----
* :func:`sdof` -- m = k = 1, c = 0.04, one link to the ground (f_s = 0.5, k_t given),
  F = 1, H = 15, 0.5 -> 2 rad/s (soft: k_t = k; stiff: k_t = 1e4 k, 1e6 k).
* :func:`chain3` -- NLvib's friction chain (its example 07,
  ``multiDOFoscillator_multipleNonlinearities``, with the two elastic dry-friction
  elements only, no cubic or unilateral springs): three unit masses on four unit springs
  grounded at both ends, C = 0.02 K, force on mass 2 (the response), Jenkins links
  ground-mass 1 and mass 1-mass 2 of stiffness knl and slip force 1, H = 7,
  0.5 <-> 2 rad/s.
* :func:`chain5` -- five unit masses on six unit springs grounded at both ends,
  C = 0.02 K, force 1 on mass 3 (the response), three Jenkins links of different
  stiffness and slip force (ground-mass 1: k = 50, f_s = 0.5; mass 2-mass 3: 500, 1;
  mass 4-mass 5: 200, 2), H = 7, 0.3 <-> 2.2 rad/s (all five modes of the free chain,
  2 sin(j pi / 12) = 0.52 ... 1.93 rad/s; the first two resonances lie between the
  free and the stuck chain's, where the links stick and slip).

* :func:`contact_point` -- a unit mass on one 3D contact point (normal z, slips x and
  y): springs k_x = 1, k_y = 1.3, k_z = 1 and an x-z coupling 0.5 [N/m]
  (:data:`CONTACT_POINT_K`), C = 0.02 I, a penalty normal spring k_n = 4 with lift-off,
  Jenkins friction k_t = 2 [N/m] with slip force mu N (mu = 0.3) following the normal
  load N; a static load of 1 N presses it down (harmonic 0), the excitation 0.3 cos
  along x and 0.2 sin along y, so the slip traces an ellipse and, through the coupling,
  the contact lifts off near the x resonance (for ~3/4 of the cycle at the peak,
  omega = 0.955 rad/s, where the mass bounces on the contact); H = 7,
  0.5 -> 1.6 rad/s. Not in :func:`all_cases` (the peers take Jenkins links only).

Cases of the example benchmarks only (``examples/bench_hb.py``, ``bench_hb_robust.py``;
not in :func:`all_cases`): :func:`sdof` with other damping, slip force, force, H and
band; :func:`two_dof` -- the 2-DOF test model, links between the masses and to the
ground; :func:`modal_chain` -- n masses with 8 Jenkins links at seeded random DOFs.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np


@dataclass(frozen=True)
class Jenkins:
    """A Jenkins link on u = x_a - x_b (b None: the ground)."""

    dof_a: int
    dof_b: int | None
    k: float
    fs: float


@dataclass(frozen=True)
class BenchCase:
    """One benchmark curve: a linear chain with Jenkins links and a cosine excitation.

    Attributes
    ----------
    name : str
        Row label.
    M, K, C : (n, n) ndarray
    force : (n,) ndarray
        Cosine excitation amplitude on harmonic 1 [N].
    links : tuple of Jenkins
    response_dof : int
    harmonics : int
        H (harmonics 0..H).
    band : (float, float)
        Start and end frequency of the sweep [rad/s] (end < start: swept down).
    """

    name: str
    M: np.ndarray = field(repr=False)
    K: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    force: np.ndarray = field(repr=False)
    links: tuple
    response_dof: int
    harmonics: int
    band: tuple

    @property
    def n(self) -> int:
        return int(np.asarray(self.M).shape[0])

    def model(self):
        """The :class:`~harmonic_balance.model.Model` of this case (C-core Jenkins elements)."""
        from .aft import FrictionLink
        from .linear import LinearModel
        from .model import Model, jenkins_element

        links = [FrictionLink(jenkins_element(j.k, j.fs), j.dof_a, j.dof_b, f"link{i}")
                 for i, j in enumerate(self.links)]
        return Model(LinearModel(M=self.M, C=self.C, K=self.K), links,
                     {1: np.asarray(self.force, dtype=complex)}, self.response_dof)

    def spec(self) -> dict:
        """JSON-able definition (what a peer code is given)."""
        return {"name": self.name, "M": np.asarray(self.M).tolist(), "K": np.asarray(self.K).tolist(),
                "C": np.asarray(self.C).tolist(), "force": np.asarray(self.force).tolist(),
                "links": [[j.dof_a, j.dof_b, j.k, j.fs] for j in self.links],
                "response_dof": self.response_dof, "harmonics": self.harmonics,
                "band": list(self.band)}


def spring_chain(n: int, k: float = 1.0) -> np.ndarray:
    """Stiffness (n, n) of n masses on n + 1 springs k, grounded at both ends."""
    return k * (2.0 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))


def sdof(kt: float = 1.0, damping: float = 0.04, slip_force: float = 0.5, force: float = 1.0,
         harmonics: int = 15, band: tuple = (0.5, 2.0), name: str | None = None) -> BenchCase:
    """Single-DOF Jenkins oscillator m = k = 1, link to the ground: by default c = 0.04,
    f_s = 0.5, F = 1, H = 15, 0.5 -> 2 (named "sdof soft" at k_t = k, else "sdof stiff 1e4"
    etc.; ``name`` overrides)."""
    if name is None:
        name = "sdof soft" if kt == 1.0 else f"sdof stiff {kt:.0e}".replace("e+0", "e")
    return BenchCase(name, np.eye(1), np.eye(1), damping * np.eye(1), np.array([float(force)]),
                     (Jenkins(0, None, kt, slip_force),), 0, harmonics, tuple(band))


def two_dof() -> BenchCase:
    """The 2-DOF test model (``tests/hb/hbcases.two_dof``): M = diag(1, 0.5), a link between
    the masses (k 0.8, f_s 0.04) and one from mass 2 to the ground (0.5, 0.08),
    C = 0.01 M + 0.005 K, force 0.05 on mass 1 (the response), H = 7, 0.6 -> 1.6 rad/s."""
    M = np.diag([1.0, 0.5])
    K = np.array([[2.0, -1.0], [-1.0, 1.5]])
    return BenchCase("2-DOF", M, K, 0.01 * M + 0.005 * K, np.array([0.05, 0.0]),
                     (Jenkins(0, 1, 0.8, 0.04), Jenkins(1, None, 0.5, 0.08)), 0, 7, (0.6, 1.6))


#: Seed of :func:`modal_chain`'s link placement.
CHAIN_SEED = 20261122


def modal_chain(n_modes: int, n_links: int = 8, harmonics: int = 7) -> BenchCase:
    """Chain of n masses (M = diag(1 ... 0.5), unit springs, C = 0.02 M + 0.001 K), force
    0.02 on DOF 0 (the response), ``n_links`` Jenkins links (k 0.3, f_s 0.005): half between
    pairs of DOFs, half to the ground, at distinct DOFs drawn with :data:`CHAIN_SEED`
    (12 for 8 links when the chain is long enough). Band: 0.9 x the free to 1.1 x the
    stuck first natural frequency (the first resonance with the links slipping and
    stuck)."""
    import scipy.linalg as sla

    n = n_modes
    M = np.diag(np.linspace(1.0, 0.5, n))
    K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    rng = np.random.default_rng(CHAIN_SEED)
    dofs = rng.choice(np.arange(1, n), size=min(n - 1, 3 * n_links // 2), replace=False)
    half = n_links // 2
    links = tuple(Jenkins(int(dofs[2 * e]), int(dofs[2 * e + 1]), 0.3, 0.005) if e < half
                  else Jenkins(int(dofs[(n_links + e - half) % dofs.size]), None, 0.3, 0.005)
                  for e in range(n_links))
    f = np.zeros(n)
    f[0] = 0.02
    case = BenchCase(f"chain {n} modes, {n_links} el.", M, K, 0.02 * M + 0.001 * K, f, links, 0,
                     harmonics, ())
    K_stuck = case.model().stuck_stiffness()
    w_free, w_stuck = (np.sqrt(sla.eigh(k, M, eigvals_only=True)[0]) for k in (K, K_stuck))
    return replace(case, band=(0.9 * w_free, 1.1 * w_stuck))


def chain3(force: float = 1.0, knl: float = 20.0, down: bool = False) -> BenchCase:
    """NLvib's 3-mass friction chain (module docstring), swept up or down."""
    K = spring_chain(3)
    links = (Jenkins(0, None, knl, 1.0), Jenkins(1, 0, knl, 1.0))
    return BenchCase(f"chain3 F={force:g} knl={knl:g} {'down' if down else 'up'}", np.eye(3), K,
                     0.02 * K, np.array([0.0, force, 0.0]), links, 1, 7,
                     (2.0, 0.5) if down else (0.5, 2.0))


#: Links of the 5-mass chain: (a, b, k [N/m], f_s [N]), different stiffness and slip force.
CHAIN5_LINKS = ((0, None, 50.0, 0.5), (2, 1, 500.0, 1.0), (4, 3, 200.0, 2.0))


def chain5(down: bool = False) -> BenchCase:
    """Five masses, three Jenkins links (module docstring), swept up or down."""
    K = spring_chain(5)
    f = np.zeros(5)
    f[2] = 1.0
    return BenchCase(f"chain5 {'down' if down else 'up'}", np.eye(5), K, 0.02 * K, f,
                     tuple(Jenkins(*j) for j in CHAIN5_LINKS), 2, 7, (2.2, 0.3) if down else (0.3, 2.2))


#: The 3-mass chain's grid: excitation levels [N] and link stiffnesses [N/m].
CHAIN3_FORCES = (0.5, 1.0, 2.0)
CHAIN3_KNL = (20.0, 200.0, 2000.0)


def chain3_grid() -> list[BenchCase]:
    """Every (force, knl, direction) of the 3-mass chain: 18 curves."""
    return [chain3(f, k, d) for f in CHAIN3_FORCES for k in CHAIN3_KNL for d in (False, True)]


def all_cases() -> list[BenchCase]:
    """Every benchmark case: the single-DOF soft and stiff curves, the 3-mass grid, the
    5-mass chain both ways."""
    return [sdof(1.0), sdof(1e4), sdof(1e6), *chain3_grid(), chain5(False), chain5(True)]


def by_name(name: str) -> BenchCase:
    """The case of :func:`all_cases` with this name (ValueError naming the known ones)."""
    cases = {c.name: c for c in all_cases()}
    if name not in cases:
        raise ValueError(f"unknown benchmark case {name!r}; known: {', '.join(cases)}")
    return cases[name]


@dataclass(frozen=True)
class ContactPointCase:
    """The 3D contact point (:func:`contact_point`): the attributes of a
    :class:`BenchCase` that the accuracy table reads (``name``, ``band``, ``harmonics``,
    ``response_dof``, :meth:`model`), with the contact's data (SI units)."""

    name: str
    K: np.ndarray = field(repr=False)
    damping: float = 0.02
    k_n: float = 4.0
    k_t: float = 2.0
    mu: float = 0.3
    preload: float = 1.0
    force: tuple = (0.3, -0.2j, 0.0)
    harmonics: int = 7
    band: tuple = (0.5, 1.6)
    response_dof: int = 0

    def model(self):
        """The :class:`~harmonic_balance.model.Model`: DOFs [x, y, z] of the mass; the
        contact's q = [x, y, -z] (:meth:`Kinematics.contact` with normal +z from the
        ground into the mass); harmonic 0 carries the static load -preload on z."""
        from .contact import ContactElement
        from .kinematics import Kinematics
        from .linear import LinearModel
        from .model import Model

        kin = Kinematics.contact([0, 1, 2], [0.0, 0.0, 1.0], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], np.eye(3))
        el = ContactElement.jenkins(kin, self.k_n, self.k_t, self.mu, name="contact",
                                    max_periods=CONTACT_POINT_PERIODS)
        lin = LinearModel(M=np.eye(3), C=self.damping * np.eye(3), K=np.asarray(self.K, dtype=float))
        return Model(lin, [el], {0: np.array([0.0, 0.0, -self.preload]),
                                 1: np.asarray(self.force, dtype=complex)}, self.response_dof)


#: Structural stiffness [N/m] of the contact point's mass: x and z coupled (an inclined
#: spring), so the x resonance moves the mass normal to the contact and lifts it off.
CONTACT_POINT_K = ((1.0, 0.0, 0.5), (0.0, 1.3, 0.0), (0.5, 0.0, 1.0))
#: Periods the contact's loop may be marched until it closes: with N varying and the slip
#: in two directions, a slider that sticks part of the cycle drifts towards its periodic
#: state slowly (at omega ~ 0.56 rad/s below the resonance: not closed to 1e-10 in 400
#: periods, closed in 4000).
CONTACT_POINT_PERIODS = 20000


def contact_point() -> ContactPointCase:
    """A mass on one 3D contact point with lift-off (module docstring)."""
    return ContactPointCase("contact3d lift-off", np.array(CONTACT_POINT_K))

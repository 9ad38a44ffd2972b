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
"""
from __future__ import annotations

from dataclasses import dataclass, field

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


def sdof(kt: float = 1.0) -> BenchCase:
    """Single-DOF Jenkins oscillator: m = k = 1, c = 0.04, f_s = 0.5, F = 1, H = 15, 0.5 -> 2
    (named "sdof soft" at k_t = k, else "sdof stiff 1e4" etc.)."""
    name = "sdof soft" if kt == 1.0 else f"sdof stiff {kt:.0e}".replace("e+0", "e")
    return BenchCase(name, np.eye(1), np.eye(1), 0.04 * np.eye(1), np.ones(1),
                     (Jenkins(0, None, kt, 0.5),), 0, 15, (0.5, 2.0))


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

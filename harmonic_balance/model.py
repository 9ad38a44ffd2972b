"""Forced-response models: a linear structure, friction links, harmonic excitation.

File formats
------------
``matrices.npz`` (numpy ``savez``), SI units, n DOFs:

* ``M``, ``K`` (n, n) and optional ``C`` (n, n, default zero): mass [kg], stiffness
  [N/m], viscous damping [N s/m]; or modal data ``phi`` (n, r) mass-normalised mode
  shapes, ``omega_r`` (r,) natural angular frequencies [rad/s], ``zeta_r`` (r,)
  modal damping ratios (c_r = 2 zeta_r omega_r).
* ``force`` (n,) real: amplitude [N] of the cosine excitation at harmonic 1, or
  (H_f, n) complex: row h - 1 is the complex amplitude F_h of harmonic h, with
  ``f(t) = Re(F_h exp(i h omega t))`` (F_h = f_cos - i f_sin).
* optional ``response_dof`` (int): DOF whose amplitude the FRF reports (default 0).

``elements.toml``: one ``[[element]]`` table per friction link::

    [[element]]
    dofs = [3, 7]            # u = x_3 - x_7; a single DOF [3] links it to the ground
    type = "jenkins"         # spring k [N/m] in series with a slider of strength fs [N]
    k = 1.0e5
    fs = 10.0

    [[element]]
    dofs = [2]
    type = "curve"           # virgin curve file read by contact_core.curve.read_curve
    path = "curves/sphere.json"  # relative to the .toml file
    fit = "concave"          # "reject" (default) or "concave" (least concave majorant)
    scale = 1.0              # friction scale: multiplies every slip strength

    [[element]]
    dofs = [4, 5]
    type = "sliders"         # Iwan parallel sliders at the reference normal load
    k = [1e5, 5e4]
    fs = [1.0, 2.0]
    k_res = 0.0

DOFs are 0-based. Symbols as in :mod:`harmonic_balance.fourier` and
:mod:`harmonic_balance.linear`.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .aft import FrictionLink
from .fourier import FourierBasis
from .linear import LinearModel


@dataclass
class Model:
    """Linear structure + friction links + harmonic excitation.

    Parameters
    ----------
    linear : LinearModel
    links : list of FrictionLink
    forcing : dict {h: (n,) complex}
        Complex excitation amplitude per harmonic, f = Re(F_h exp(i h omega t)) [N].
    response_dof : int
        DOF reported as the response.
    """

    linear: LinearModel
    links: list = field(default_factory=list)
    forcing: dict = field(default_factory=dict)
    response_dof: int = 0

    def __post_init__(self):
        n = self.linear.n
        for link in self.links:
            for d in link.dofs:
                if not 0 <= d < n:
                    raise ValueError(f"friction link {link.name!r} DOF {d} outside 0..{n - 1}")
            if link.dof_b is not None and link.dof_b == link.dof_a:
                raise ValueError(f"friction link {link.name!r} joins DOF {link.dof_a} to itself")
        if not 0 <= self.response_dof < n:
            raise ValueError(f"response DOF {self.response_dof} outside 0..{n - 1}")
        forcing = {}
        for h, f in self.forcing.items():
            f = np.asarray(f, dtype=complex).reshape(-1)
            if int(h) < 0 or f.size != n or not np.all(np.isfinite(f)):
                raise ValueError(f"forcing of harmonic {h} must be {n} finite values")
            forcing[int(h)] = f
        if not forcing or all(np.all(f == 0) for f in forcing.values()):
            raise ValueError("the model has no excitation")
        self.forcing = forcing

    @property
    def n(self) -> int:
        return self.linear.n

    def stuck_stiffness(self) -> np.ndarray:
        """Stiffness (n, n) [N/m] with every friction link stuck at its initial stiffness k0."""
        K = np.array(self.linear.K, dtype=float, copy=True)
        for link in self.links:
            a, b = link.dof_a, link.dof_b
            K[a, a] += link.k0
            if b is not None:
                K[b, b] += link.k0
                K[a, b] -= link.k0
                K[b, a] -= link.k0
        return K

    def forcing_coeffs(self, basis: FourierBasis) -> np.ndarray:
        """Excitation harmonics (n_b, n) in the basis ordering [N]."""
        F = np.zeros((basis.nb, self.n))
        for h, f in self.forcing.items():
            ic, isn = basis.index(h)  # ValueError if the excitation is not retained
            F[ic] = f.real
            if isn is not None:
                F[isn] = -f.imag
            elif np.any(f.imag != 0):
                raise ValueError("a static (h = 0) load must be real")
        return F


def jenkins_element(k: float, fs: float):
    """C-core Jenkins element (spring k [N/m], slip force fs [N])."""
    from fmu_src.element import IwanElement

    if not (np.isfinite(k) and np.isfinite(fs)) or k <= 0 or fs < 0:
        raise ValueError(f"Jenkins element needs k > 0 and fs >= 0, got k={k}, fs={fs}")
    return IwanElement.jenkins(k, fs)


def sdof_model(mass, stiffness, damping, contact_stiffness, slip_force, force) -> Model:
    """Oscillator m x'' + c x' + k x + F_jenkins(x) = P cos(omega t), element to ground."""
    for name, v in (("mass", mass), ("stiffness", stiffness), ("damping", damping),
                    ("force", force)):
        if not np.isfinite(v) or v < 0 or (name == "mass" and v == 0):
            raise ValueError(f"{name} must be finite and {'> 0' if name == 'mass' else '>= 0'}, got {v}")
    lin = LinearModel(M=[[mass]], C=[[damping]], K=[[stiffness]])
    links = [FrictionLink(jenkins_element(contact_stiffness, slip_force), 0, None, "jenkins")]
    return Model(lin, links, {1: np.array([force], dtype=complex)}, 0)


def load_matrices(path) -> tuple[LinearModel, dict, int]:
    """Read a ``matrices.npz`` file (format in the module docstring)."""
    path = Path(path)
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as err:
        raise ValueError(f"cannot read model file {path}: {err}") from None
    keys = set(data.files)
    if {"M", "K"} <= keys:
        lin = LinearModel(M=data["M"], C=data["C"] if "C" in keys else None, K=data["K"])
    elif {"phi", "omega_r"} <= keys:
        w = np.asarray(data["omega_r"], dtype=float)
        z = np.asarray(data["zeta_r"], dtype=float) if "zeta_r" in keys else np.zeros_like(w)
        lin = LinearModel(phi=data["phi"], w_r=w, c_r=2.0 * z * w)
    else:
        raise ValueError(f"{path}: need arrays M and K (and C), or phi and omega_r (and zeta_r)")
    if "force" not in keys:
        raise ValueError(f"{path}: no 'force' array")
    f = np.atleast_1d(np.asarray(data["force"]))
    forcing = {1: f} if f.ndim == 1 else {h + 1: row for h, row in enumerate(f)}
    resp = int(data["response_dof"]) if "response_dof" in keys else 0
    return lin, forcing, resp


def load_elements(path) -> list[FrictionLink]:
    """Read an ``elements.toml`` file into friction links (format in the module docstring)."""
    path = Path(path)
    try:
        spec = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as err:
        raise ValueError(f"cannot read elements file {path}: {err}") from None
    tables = spec.get("element", [])
    if not tables:
        raise ValueError(f"{path}: no [[element]] tables")
    return [_element_link(t, i, path.parent) for i, t in enumerate(tables)]


def _element_link(t: dict, i: int, base: Path) -> FrictionLink:
    """One [[element]] table -> FrictionLink."""
    from fmu_src.element import IwanElement

    dofs = t.get("dofs")
    if not isinstance(dofs, list) or len(dofs) not in (1, 2):
        raise ValueError(f"element {i}: 'dofs' must be [a] or [a, b]")
    kind = t.get("type", "jenkins")
    name = t.get("name", f"element{i}")
    if kind == "jenkins":
        el = jenkins_element(float(t["k"]), float(t["fs"]))
    elif kind == "sliders":
        el = IwanElement.from_sliders(np.asarray(t["k"], float), np.asarray(t["fs"], float),
                                      k_res=float(t.get("k_res", 0.0)))
    elif kind == "curve":
        from contact_core.curve import read_curve

        c = read_curve(base / t["path"])
        # Same rule as damper loop / damper fmu: N_ref = the curve's N (1 if none),
        # the curve file's own tail (flat at gross slip or last slope), reduced to
        # the element's limit when longer (el.fit_error).
        el = IwanElement.from_virgin_curve(c, fit=t.get("fit", "reject"), scale=float(t.get("scale", 1.0)))
    else:
        raise ValueError(f"element {i}: unknown type {kind!r} (jenkins, sliders, curve)")
    b = int(dofs[1]) if len(dofs) == 2 else None
    return FrictionLink(el, int(dofs[0]), b, name)


def load_model(matrices, elements) -> Model:
    """Model from a ``.npz`` and an ``.toml`` file."""
    lin, forcing, resp = load_matrices(matrices)
    return Model(lin, load_elements(elements), forcing, resp)

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

    [[element]]
    type = "contact"         # penalty normal with lift-off + friction following N
    dofs = [0, 1]            # DOFs of the contact point's relative displacement Delta
    normal = [0.0, 1.0]      # unit normal n from body 2 into body 1 (k = 2 or 3 entries)
    tangent = [1.0, 0.0]     # unit tangent (omit it, and the friction, for normal only);
                             # two tangents [[1, 0, 0], [0, 0, 1]] (k = 3): slip in the plane
    delta = [[1, 0], [0, 1]] # (k, len(dofs)): Delta = delta @ x[dofs]; default identity
    k_n = 1.0e8              # normal penalty stiffness [N/m]
    k_t = 8.0e7              # Jenkins friction k_t [N/m] and mu, or instead
    mu = 0.5                 #   curve = "curves/flat.json" (Iwan, scaled by N / N_ref)
    preload = 0.0            # static penetration at x = 0 [m]
    slip_ref = 0.0           # prestress slip where the sliders are virgin [m] ([sx, sy]: two tangents)
    beta_c = 0.0             # contact dashpots beta_c k_n, beta_c k_t [s]

DOFs are 0-based. Symbols as in :mod:`harmonic_balance.fourier` and
:mod:`harmonic_balance.linear`.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .aft import FrictionLink
from .contact import ContactElement
from .forces import ForceElement, LinearElement
from .fourier import FourierBasis
from .kinematics import Kinematics
from .linear import LinearModel

#: Largest magnitude of an entry of M, K or C: the harmonic balance squares forces and
#: displacements (residual norms, Omega^2 M), which overflows double precision above ~1e154
#: (M scaled by 1e300 overflowed in the first corrector step).
MAX_ENTRY = 1e100
#: Largest bound on the squared natural frequencies, lambda_max(K) / lambda_min(M)
#: [rad^2/s^2], and on the modal damping, lambda_max(C) / lambda_min(M) squared: the
#: modal data are squared in norms (M scaled by 1e-300 gave NaN in the first harmonic
#: balance step, a mass of 1e-160 kg an overflow warning).
MAX_OMEGA_SQUARED = 1e100
#: A symmetric K or C may have negative eigenvalues down to this fraction of its largest
#: (round-off of an assembly, ~1e-13); below that it is not positive semi-definite.
PSD_TOL = 1e-9


@dataclass
class Model:
    """Linear structure + force elements + harmonic excitation.

    Parameters
    ----------
    linear : LinearModel
    links : list of ForceElement
        Force elements (:mod:`.forces`): friction links, contacts, linear couplings
        (the field keeps its historical name; :attr:`elements` is the same list).
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
            if not isinstance(link, ForceElement):
                raise TypeError(f"{type(link).__name__} is not a force element (harmonic_balance.forces)")
            for d in link.dofs:
                if not 0 <= d < n:
                    raise ValueError(f"friction link {link.name!r} DOF {d} outside 0..{n - 1}")
            if isinstance(link, FrictionLink) and link.dof_b is not None and link.dof_b == link.dof_a:
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

    @property
    def elements(self) -> list:
        """The force elements (the ``links`` list)."""
        return self.links

    def stuck_stiffness(self) -> np.ndarray:
        """Stiffness (n, n) [N/m] with every element stuck (``ForceElement.stuck_stiffness``).

        Non-cyclic elements only (a cyclic coupling has no single real matrix).
        """
        K = np.array(self.linear.K, dtype=float, copy=True)
        for el in self.links:
            if isinstance(el, FrictionLink):  # the historical assembly, bit for bit
                a, b = el.dof_a, el.dof_b
                K[a, a] += el.k0
                if b is not None:
                    K[b, b] += el.k0
                    K[a, b] -= el.k0
                    K[b, a] -= el.k0
                continue
            K += _on_dofs(el.kinematics, el.stuck_stiffness(), self.n)
        return K

    def harmonic_stiffness(self, h: int, stuck: bool = True) -> np.ndarray:
        """Complex stiffness (n, n) [N/m] acting on harmonic h, cyclic couplings included.

        ``K + sum_e T_h k_e Q_h`` with ``Q_h = Q + exp(i h phi) Q_next`` and
        ``T_h = T + exp(-i h phi) T_next`` (:mod:`.kinematics`), k_e the element's
        ``stuck_stiffness`` (``stuck=False``: linear elements only, the contacts and
        friction links removed). Hermitian for conservative kinematics; its
        eigenvalues with M give the stuck / free natural frequencies of the nodal
        diameter whose phase is h phi.
        """
        K = np.array(self.linear.K, dtype=complex, copy=True)
        for el in self.links:
            if not stuck and not isinstance(el, LinearElement):
                continue
            kin = el.kinematics
            Q, T = kin.Q.astype(complex), kin.T.astype(complex)
            if kin.cyclic:
                Q = Q + np.exp(1j * h * kin.phase) * kin.Q_next
                T = T + np.exp(-1j * h * kin.phase) * kin.T_next
            K[np.ix_(kin.dofs, kin.dofs)] += T @ el.stuck_stiffness() @ Q
        return K

    def element_damping(self) -> np.ndarray:
        """Viscous damping (n, n) [N s/m] of the elements' linear dashpots (``local_damping``)."""
        C = np.zeros((self.n, self.n))
        for el in self.links:
            c = el.local_damping()
            if c is not None:
                C += _on_dofs(el.kinematics, c, self.n)
        return C

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


def _on_dofs(kin, A_local: np.ndarray, n: int) -> np.ndarray:
    """T A Q of a local matrix (m, m) on all n DOFs (non-cyclic kinematics)."""
    if kin.cyclic:
        raise ValueError("a cyclic element has no single (n, n) matrix: use the harmonic residual")
    out = np.zeros((n, n))
    idx = np.ix_(kin.dofs, kin.dofs)
    out[idx] = kin.T @ A_local @ kin.Q
    return out


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
    check_scales(np.array([[mass]]), np.array([[stiffness + contact_stiffness]]), np.array([[damping]]),
                 ("mass", "stiffness + contact stiffness", "damping"))
    lin = LinearModel(M=[[mass]], C=[[damping]], K=[[stiffness]])
    links = [FrictionLink(jenkins_element(contact_stiffness, slip_force), 0, None, "jenkins")]
    return Model(lin, links, {1: np.array([force], dtype=complex)}, 0)


def load_matrices(path) -> tuple[LinearModel, dict, int]:
    """Read a ``matrices.npz`` file (format in the module docstring).

    Checked here, so a bad file is refused before any solve: M, K, C finite, symmetric
    and square; M positive definite (a mass matrix; a singular or negative M has no
    dynamics to solve); modal data finite, frequencies and damping >= 0; ``force``
    finite with one entry per DOF.
    """
    import zipfile

    from contact_core.fileio import open_npz

    path = Path(path)
    try:
        with open_npz(path, "model file") as data:
            arrays = {k: data[k] for k in data.files}
    except OSError as err:
        raise ValueError(f"cannot read model file {path}: {err.strerror}" if err.strerror else str(err)) from None
    except (ValueError, EOFError, zipfile.BadZipFile) as err:
        msg = str(err)
        raise ValueError(msg if str(path) in msg else
                         f"cannot read model file {path} (a numpy .npz archive): {msg}") from None
    if not arrays:
        raise ValueError(f"{path}: an empty .npz archive")
    try:
        return _matrices_from(arrays, path)
    except (TypeError, ValueError) as err:
        msg = str(err)
        raise ValueError(msg if msg.startswith(str(path)) else f"{path}: {msg}") from None


#: Arrays of a model file that must be real (the structure's matrices and modal data; the
#: force may be complex: its phase).
REAL_ARRAYS = ("M", "K", "C", "phi", "omega_r", "zeta_r")


def check_scales(M: np.ndarray, K: np.ndarray, C: np.ndarray, names=("M", "K", "C")) -> None:
    """Refuse a structure that is not one: K or C not positive semi-definite (a negative
    stiffness or damping feeds energy in: no steady state to continue), an entry above
    :data:`MAX_ENTRY`, or natural frequencies beyond :data:`MAX_OMEGA_SQUARED`.

    Parameters
    ----------
    M, K, C : (n, n) arrays
        Symmetric mass [kg], stiffness [N/m] and damping [N s/m] matrices; M positive definite.
    names : three str
        What the messages call M, K and C.
    """
    eig = {}
    for name, A in zip(names, (M, K, C)):
        big = float(np.abs(A).max())
        if big > MAX_ENTRY:
            raise ValueError(f"{name} has an entry of magnitude {big:.3g}, above {MAX_ENTRY:g}: the harmonic balance "
                             "squares forces and displacements, which overflows; check the units")
        eig[name] = np.linalg.eigvalsh(A)
    m, k, c = names
    what = {k: "a stiffness: a negative one has no stable rest",
            c: "a damping: a negative one feeds energy in, no steady state"}
    for name, kind in what.items():
        low, top = float(eig[name][0]), float(np.abs(eig[name]).max())
        if low < -PSD_TOL * top:
            raise ValueError(f"{name} must be positive semi-definite ({kind}), but its smallest eigenvalue is "
                             f"{low:.3g}")
    with np.errstate(over="ignore"):
        for name, power in ((k, 1), (c, 2)):
            ratio = (float(eig[name][-1]) / float(eig[m][0])) ** power if eig[name][-1] > 0 else 0.0
            if not ratio <= MAX_OMEGA_SQUARED:
                how = ("" if M.size == 1 else f" ({name}'s largest eigenvalue over {m}'s smallest)") \
                    + (", squared," if power == 2 else "")
                raise ValueError(f"{name} over {m}{how} is above {MAX_OMEGA_SQUARED:g} rad^2/s^2: "
                                 "natural frequencies or damping rates far beyond any structure; check the units")


def refuse_complex(data: dict, names, where: str) -> None:
    """ValueError when one of ``names`` in ``data`` is complex (e.g. K (1 + i eta), a loss
    factor): hysteretic damping is not modelled, and making it real would drop it silently."""
    for k in names:
        if k in data and data[k] is not None and np.iscomplexobj(data[k]):
            raise ValueError(f"{where}: {k} is complex (a loss factor, i.e. hysteretic damping, is not "
                             f"supported): give a real {k} and the damping as a real matrix C "
                             "(viscous; e.g. C = eta K / omega at the frequency of interest)")


def _matrices_from(data: dict, path: Path) -> tuple[LinearModel, dict, int]:
    keys = set(data)
    refuse_complex(data, REAL_ARRAYS, str(path))
    if {"M", "K"} <= keys:
        if np.asarray(data["M"]).size == 0 or np.asarray(data["K"]).size == 0:
            raise ValueError("M and K are 0 x 0: a model needs at least one DOF")
        with np.errstate(all="ignore"):  # its modal norms overflow for scales check_scales refuses next
            lin = LinearModel(M=data["M"], C=data["C"] if "C" in keys else None, K=data["K"])
        try:
            np.linalg.cholesky(lin.M)
        except np.linalg.LinAlgError:
            low = float(np.linalg.eigvalsh(lin.M).min())
            raise ValueError(f"M must be positive definite (a mass matrix), but its smallest eigenvalue "
                             f"is {low:.3g}; give every DOF a positive mass") from None
        check_scales(lin.M, lin.K, lin.C)
    elif {"phi", "omega_r"} <= keys:
        w = np.asarray(data["omega_r"], dtype=float)
        z = np.asarray(data["zeta_r"], dtype=float) if "zeta_r" in keys else np.zeros_like(w)
        lin = LinearModel(phi=data["phi"], w_r=w, c_r=2.0 * z * w)
    else:
        raise ValueError(f"{path}: need arrays M and K (and C), or phi and omega_r (and zeta_r)")
    if "force" not in keys:
        raise ValueError(f"{path}: no 'force' array")
    f = np.atleast_1d(np.asarray(data["force"]))
    if f.ndim > 2 or f.shape[-1] != lin.n or not np.all(np.isfinite(f)):
        raise ValueError(f"'force' must be {lin.n} finite values (or rows of {lin.n}, one per harmonic), "
                         f"got shape {f.shape}" + ("" if np.all(np.isfinite(f)) else " with non-finite entries"))
    forcing = {1: f} if f.ndim == 1 else {h + 1: row for h, row in enumerate(f)}
    resp = data.get("response_dof")
    if resp is not None and (np.asarray(resp).size != 1 or not np.issubdtype(np.asarray(resp).dtype, np.integer)):
        raise ValueError(f"'response_dof' must be one integer, got {np.asarray(resp).tolist()}")
    resp = int(resp) if resp is not None else 0
    return lin, forcing, resp


def load_elements(path) -> list[ForceElement]:
    """Read an ``elements.toml`` file into force elements (format in the module docstring;
    keys and types: :class:`harmonic_balance.elements_model.ElementsFile`)."""
    from contact_core.fileformat import parse
    from harmonic_balance.elements_model import ElementsFile

    path = Path(path)
    try:
        from contact_core.fileio import read_text_bounded

        spec = tomllib.loads(read_text_bounded(path, what="elements file"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as err:
        raise ValueError(f"cannot read elements file {path} (TOML): {err}") from None
    parse(ElementsFile, spec, str(path))   # tables, keys, types, ranges (elements_model)
    tables = spec["element"]
    links = []
    for i, t in enumerate(tables):
        try:
            links.append(_element_link(t, i, path.parent))
        except KeyError as err:
            raise ValueError(f"{path}: element {i}: missing key {err.args[0]!r}") from None
        except (TypeError, ValueError) as err:
            msg = str(err)
            raise ValueError(f"{path}: {msg if msg.startswith('element') else f'element {i}: {msg}'}") from None
    return links


def _element_link(t: dict, i: int, base: Path) -> ForceElement:
    """One [[element]] table (checked by elements_model) -> FrictionLink (or ContactElement)."""
    from fmu_src.element import IwanElement

    if t.get("type") == "contact":
        return _contact_element(t, i, base)
    kind = t.get("type", "jenkins")
    dofs = t["dofs"]
    name = t.get("name", f"element{i}")
    if kind == "jenkins":
        el = jenkins_element(float(t["k"]), float(t["fs"]))
    elif kind == "sliders":
        el = IwanElement.from_sliders(np.asarray(t["k"], float), np.asarray(t["fs"], float),
                                      k_res=float(t.get("k_res", 0.0)))
    else:  # "curve"
        from contact_core.curve import read_curve

        c = read_curve(base / t["path"])
        # Same rule as damper loop / damper fmu: N_ref = the curve's N (1 if none),
        # the curve file's own tail (flat at gross slip or last slope), reduced to
        # the element's limit when longer (el.fit_error).
        el = IwanElement.from_virgin_curve(c, fit=t.get("fit", "reject"), scale=float(t.get("scale", 1.0)))
    b = int(dofs[1]) if len(dofs) == 2 else None
    return FrictionLink(el, int(dofs[0]), b, name)


def _contact_element(t: dict, i: int, base: Path):
    """One [[element]] table of type "contact" (checked by elements_model) -> ContactElement."""
    try:
        dofs = [int(d) for d in t["dofs"]]
        normal = np.asarray(t["normal"], dtype=float)
        delta = np.asarray(t["delta"], dtype=float) if "delta" in t else np.eye(normal.size, len(dofs))
        tangent = np.asarray(t["tangent"], dtype=float) if "tangent" in t else np.zeros((0, normal.size))
        kin = Kinematics.contact(dofs, normal, tangent, delta)
        kw = {k: float(t.get(k, 0.0)) for k in ("preload", "beta_c")}
        kw["slip_ref"] = np.asarray(t.get("slip_ref", 0.0), dtype=float)
        kw["name"] = t.get("name", f"element{i}")
        if "tangent" not in t:
            return ContactElement(kin, float(t["k_n"]), **kw)
        if "curve" in t:  # the curve element exactly as a "curve" friction link reads it
            spec = {k: t[k] for k in ("fit", "scale") if k in t}
            el = _element_link({"dofs": [0], "type": "curve", "path": t["curve"], **spec}, i, base)
            return ContactElement(kin, float(t["k_n"]), el.element, **kw)
        return ContactElement.jenkins(kin, float(t["k_n"]), float(t["k_t"]), float(t["mu"]), **kw)
    except KeyError as err:
        raise ValueError(f"element {i}: contact needs key {err.args[0]!r}") from None
    except (TypeError, ValueError) as err:
        msg = str(err)
        raise ValueError(msg if msg.startswith(f"element {i}:") else f"element {i}: {msg}") from None


def load_model(matrices, elements) -> Model:
    """Model from a ``.npz`` and an ``.toml`` file."""
    lin, forcing, resp = load_matrices(matrices)
    return Model(lin, load_elements(elements), forcing, resp)

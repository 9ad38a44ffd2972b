"""The blade of a UPD sector: reduced linear matrices with the platform DOFs named.

Every sector model (the bundled UPD-24 included) is a :class:`Blade` of n reduced
DOFs plus the damper's three (x_d, y_d, theta_d). A blade is

* ``M``, ``K`` (n, n): symmetric mass [kg] and stiffness [N/m] of blade j (with its
  share of the disk), M positive definite;
* ``C`` (n, n), optional: viscous damping [N s/m]; none: ``C = beta K`` with
  ``blade.beta`` of the config (and ``C_next = beta K_next``);
* ``K_next``, ``C_next`` (n, n), optional: coupling to blade j+1 (its DOFs in the
  same order): the ring's stiffness has blocks K on the diagonal, K_next at
  (j, j+1) and K_next^T at (j+1, j), so per interblade phase psi::

      K(psi) = K + K_next exp(i psi) + K_next^T exp(-i psi)               (B1)

  and C(psi) likewise. None: no coupling (blade clamped on a rigid disk).
  Example, UPD-24's rim springs k_c to both neighbours on u_r: ``K`` holds
  ``k_g + 2 k_c`` and ``K_next`` holds ``-k_c``, so K(psi) = k_g + 2 k_c (1 - cos psi);
* named DOFs ``dofs`` (n names) and the roles, by name:
  ``left = [u, v]`` the platform point of blade j that damper j's left (cylinder)
  contact touches, ``right = [u, v]`` the platform point of blade j that damper
  j-1's flat touches (so damper j's flat touches it on blade j+1); u tangential
  (towards blade j+1), v radial outward [m] (the damper's x and y axes); with a
  third name each, ``[u, v, w]``, w axial [m]: the damper is held axially, so its
  contacts slip along (in the plane) and across (axially; two tangents each);
  ``forced`` the DOF of the EO force F0; ``response`` the amplitude output
  (default: the forced DOF).

Files (the TOML ``[blade]`` section, paths relative to the TOML file)
----------------------------------------------------------------------
``file = "blade.npz"``: a numpy ``.npz`` with arrays ``M``, ``K`` and optionally
``C``, ``K_next``, ``C_next``, ``dofs`` (n strings), ``left``, ``right`` (2 strings),
``forced``, ``response`` (strings). Or Matrix Market files (``scipy.io.mmwrite``),
``M = "M.mtx"``, ``K = "K.mtx"``, optionally ``C``, ``K_next``, ``C_next``. The TOML
keys ``dofs``, ``left``, ``right``, ``forced``, ``response`` override the file's;
without ``dofs`` the names are ``q0 .. q{n-1}``. Neither ``file`` nor ``M``: the
built-in lumped blade of the ``[blade]`` keys ``m_r .. k_pa`` (UPD-24,
:func:`lumped_arrays`). :func:`write_npz` and :func:`write_mtx` write a blade.
:func:`craig_bampton` reduces FE matrices to such a blade.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..model import refuse_complex

#: Matrix keys of a blade file, required first.
MATRICES = ("M", "K", "C", "K_next", "C_next")
#: Role keys (names of DOFs).
ROLES = ("dofs", "left", "right", "forced", "response")
#: Relative asymmetry |A - A^T| / |A| accepted (round-off of a reduction T^T A T).
SYM_RTOL = 1e-8
#: Relative negative eigenvalue accepted in K(0), C(0) (round-off; rigid-body modes
#: of a free blade on a free disk are 0 to this level) and positive-definiteness of M.
PSD_RTOL = 1e-10


@dataclass
class Blade:
    """Reduced linear blade (module docstring). Shapes (n, n); indices into 0..n-1.

    Attributes
    ----------
    M, K : (n, n) arrays; C, K_next, C_next : (n, n) arrays or None
    dofs : tuple of str (n,)
    left, right : (2,) or (3,) int   (u, v[, w]) platform DOF indices of the two contacts
    forced, response : int
    source : str               where it came from (messages)
    """

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray | None
    K_next: np.ndarray | None
    C_next: np.ndarray | None
    dofs: tuple
    left: tuple
    right: tuple
    forced: int
    response: int
    source: str = "built-in"

    @property
    def n(self) -> int:
        return self.M.shape[0]

    def damping_parts(self, beta: float):
        """(C, C_next) with the default C = beta K, C_next = beta K_next when C is None."""
        if self.C is None:
            return beta * self.K, None if self.K_next is None else beta * self.K_next
        return self.C, self.C_next

    def stiffness(self, psi: float) -> np.ndarray:
        """K(psi) (n, n) of (B1); real when K_next is symmetric, else complex Hermitian."""
        return _cyclic(self.K, self.K_next, psi)

    def damping(self, psi: float, beta: float) -> np.ndarray:
        """C(psi) (n, n) of (B1); beta K(psi) when the blade has no C."""
        if self.C is None:
            return beta * self.stiffness(psi)
        return _cyclic(self.C, self.C_next, psi)


def _cyclic(A, A_next, psi):
    if A_next is None:
        return A.copy()
    if psi == 0.0:
        return A + A_next + A_next.T
    if np.array_equal(A_next, A_next.T):
        return A + 2.0 * np.cos(psi) * A_next
    e = np.exp(1j * psi)
    return A + e * A_next + np.conj(e) * A_next.T


# ------------------------------------------------------------------ built-in
def lumped_arrays(b: dict) -> dict:
    """UPD-24's lumped blade from the ``[blade]`` keys: DOFs u_r, u_p, v_p, u_a.

    Springs: k_g u_r to the hub, k_rp u_r - u_p, k_pa u_p - u_a, k_v v_p to ground,
    k_c u_r to u_r of each neighbour (K_next[0, 0] = -k_c, K[0, 0] += 2 k_c).
    Masses m_r, m_p (u_p and v_p), m_a. Platform point of both contacts (u_p, v_p),
    EO force and response on u_a.
    """
    K = np.zeros((4, 4))
    K[0, 0] = b["k_g"] + 2.0 * b["k_c"]
    for i, j, k in ((0, 1, b["k_rp"]), (1, 3, b["k_pa"])):
        K[np.ix_([i, j], [i, j])] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    K[2, 2] += b["k_v"]
    K_next = np.zeros((4, 4))
    K_next[0, 0] = -float(b["k_c"])
    M = np.diag([b["m_r"], b["m_p"], b["m_p"], b["m_a"]]).astype(float)
    return {"M": M, "K": K, "K_next": K_next, "dofs": ["u_r", "u_p", "v_p", "u_a"],
            "left": ["u_p", "v_p"], "right": ["u_p", "v_p"], "forced": "u_a"}


# ------------------------------------------------------------------ files
def load_blade(section: dict, base: Path | None = None) -> Blade:
    """The blade of a config's ``[blade]`` section (file, Matrix Market or built-in).

    Parameters
    ----------
    section : dict      the ``[blade]`` table
    base : Path         directory of relative paths (the TOML's); default the cwd

    Raises
    ------
    ValueError naming the file, array or DOF that is unusable.
    """
    base = Path(base or ".")
    for k in ("file",) + MATRICES + ("forced", "response"):
        if not isinstance(section.get(k, ""), str):
            raise ValueError(f"blade: {k} = {section[k]!r} must be a string")
    for k in ("dofs", "left", "right"):
        v = section.get(k, [])
        if not (isinstance(v, list) and all(isinstance(e, str) for e in v)):
            raise ValueError(f"blade: {k} = {v!r} must be a list of DOF names (strings)")
    given = {k: section.get(k) for k in MATRICES if section.get(k)}
    file = section.get("file") or ""
    if file and given:
        raise ValueError(f"blade: give either file = {file!r} or Matrix Market "
                         f"{', '.join(given)}, not both")
    if not file and not given:
        arrays, source = lumped_arrays(section), "built-in (lumped UPD-24 keys)"
    elif file:
        path = base / file
        arrays, source = _read_npz(path), str(path)
    else:
        if "M" not in given or "K" not in given:
            raise ValueError("blade: Matrix Market input needs both M and K files")
        arrays = {k: _read_mtx(base / v, k) for k, v in given.items()}
        source = str(base / given["M"])
    for k in ROLES:  # the TOML's names override the file's
        v = section.get(k)
        if v not in (None, "", []):
            arrays[k] = v
    return make_blade(arrays, source)


def _read_npz(path: Path) -> dict:
    from contact_core.fileio import open_npz

    try:
        with open_npz(path, "blade file") as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError) as err:
        msg = getattr(err, "strerror", None) or str(err)
        raise ValueError(msg if str(path) in msg else f"blade file {path}: cannot read ({msg})") from None
    unknown = set(data) - set(MATRICES) - set(ROLES)
    if unknown:
        raise ValueError(f"blade file {path}: unknown arrays {sorted(unknown)} "
                         f"(known: {', '.join(MATRICES + ROLES)})")
    for k in ROLES:
        if k in data:
            v = data[k]
            data[k] = v.tolist() if v.ndim else str(v)
    return data


def _read_mtx(path: Path, key: str) -> np.ndarray:
    import scipy.io

    from contact_core.fileio import check_matrix_market

    try:
        check_matrix_market(path, dense=True, what=f"blade {key} =")
        A = scipy.io.mmread(str(path))
    except (OSError, ValueError) as err:
        msg = getattr(err, "strerror", None) or str(err)
        raise ValueError(msg if str(path) in msg else
                         f"blade {key} = {path}: cannot read Matrix Market ({msg})") from None
    return A.toarray() if hasattr(A, "toarray") else np.asarray(A)


def make_blade(arrays: dict, source: str = "arrays") -> Blade:
    """Check and assemble a :class:`Blade` from arrays and role names (module docstring)."""
    where = f"blade {source}"
    if "M" not in arrays or "K" not in arrays:
        raise ValueError(f"{where}: M and K are required")
    n = np.shape(arrays["M"])[0] if np.ndim(arrays["M"]) == 2 else -1
    refuse_complex(arrays, MATRICES, where)
    mats = {}
    for k in MATRICES:
        if arrays.get(k) is None:
            mats[k] = None
            continue
        try:
            A = np.asarray(arrays[k], dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"{where}: {k} is not a numeric matrix") from None
        if A.ndim != 2 or A.shape[0] != A.shape[1] or (n > 0 and A.shape != (n, n)):
            raise ValueError(f"{where}: {k} has shape {A.shape}, expected ({n}, {n}) "
                             "(square, the size of M)")
        if not np.all(np.isfinite(A)):
            raise ValueError(f"{where}: {k} has NaN or infinite entries")
        mats[k] = A
    for k in ("M", "K", "C"):
        if mats[k] is not None:
            mats[k] = _symmetric(mats[k], f"{where}: {k}")
    if n < 1:
        raise ValueError(f"{where}: M is empty")
    names = arrays.get("dofs")
    names = [f"q{i}" for i in range(n)] if names is None else [str(s) for s in np.atleast_1d(names)]
    if len(names) != n or len(set(names)) != n:
        raise ValueError(f"{where}: dofs must be {n} distinct names, got {len(names)} "
                         f"({len(set(names))} distinct)")
    idx = {s: i for i, s in enumerate(names)}

    def lookup(role, count):
        v = arrays.get(role)
        if v is None or (role == "response" and v in ("", [])):
            if role == "response":
                return None
            raise ValueError(f"{where}: the DOF role {role!r} is not given")
        v = [v] if isinstance(v, str) else list(v)
        if len(v) not in ((count,) if isinstance(count, int) else count):
            want = count if isinstance(count, int) else " or ".join(map(str, count))
            raise ValueError(f"{where}: {role} must name {want} DOF(s), got {v}")
        for s in v:
            if str(s) not in idx:
                raise ValueError(f"{where}: {role} names unknown DOF {s!r} "
                                 f"(known: {', '.join(names[:12])}{' ...' if n > 12 else ''})")
        return tuple(idx[str(s)] for s in v)

    left, right = lookup("left", (2, 3)), lookup("right", (2, 3))
    if len(left) != len(right):
        raise ValueError(f"{where}: left and right must both name (u, v) or both (u, v, w), "
                         f"got {len(left)} and {len(right)} DOFs")
    forced = lookup("forced", 1)[0]
    response = lookup("response", 1)
    blade = Blade(mats["M"], mats["K"], mats["C"], mats["K_next"], mats["C_next"], tuple(names),
                  left, right, forced, forced if response is None else response[0], source)
    _check_definite(blade, where)
    return blade


def _symmetric(A: np.ndarray, what: str) -> np.ndarray:
    scale = np.abs(A).max()
    asym = np.abs(A - A.T).max()
    if asym > SYM_RTOL * scale:
        raise ValueError(f"{what} is not symmetric (max |A - A^T| / max |A| = {asym / scale:.2e})")
    return A if asym == 0 else 0.5 * (A + A.T)


def _check_definite(blade: Blade, where: str) -> None:
    """M positive definite; K(0) and C(0) positive semi-definite (else refuse)."""
    lam = np.linalg.eigvalsh(blade.M)
    if lam[0] <= PSD_RTOL * max(lam[-1], 0.0):
        raise ValueError(f"{where}: M is not positive definite (smallest eigenvalue {lam[0]:.3e}, "
                         f"largest {lam[-1]:.3e})")
    for name, A in (("K", _cyclic(blade.K, blade.K_next, 0.0)),
                    ("C", None if blade.C is None else _cyclic(blade.C, blade.C_next, 0.0))):
        if A is None:
            continue
        lam = np.linalg.eigvalsh(A)
        if lam[0] < -PSD_RTOL * max(abs(lam[-1]), 1e-300):
            raise ValueError(f"{where}: {name} + {name}_next + {name}_next^T is indefinite "
                             f"(eigenvalue {lam[0]:.3e}, largest {lam[-1]:.3e})")


def blade_arrays(blade: Blade) -> dict:
    """The blade as the arrays of a blade file (matrices that are None left out)."""
    out = {k: getattr(blade, k) for k in MATRICES if getattr(blade, k) is not None}
    out.update(dofs=np.array(blade.dofs), left=np.array([blade.dofs[i] for i in blade.left]),
               right=np.array([blade.dofs[i] for i in blade.right]),
               forced=np.array(blade.dofs[blade.forced]), response=np.array(blade.dofs[blade.response]))
    return out


def write_npz(blade: Blade, path) -> Path:
    """Write ``blade`` as a ``.npz`` blade file (the format of :func:`load_blade`)."""
    path = Path(path)
    np.savez(path, **blade_arrays(blade))
    return path


def write_mtx(blade: Blade, directory) -> dict:
    """Write the blade's matrices as Matrix Market files ``<key>.mtx`` in ``directory``;
    return the ``[blade]`` TOML keys (paths relative to ``directory``, the DOF names)."""
    import scipy.io

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    keys = {}
    for k in MATRICES:
        A = getattr(blade, k)
        if A is not None:
            scipy.io.mmwrite(str(directory / f"{k}.mtx"), A, precision=17)
            keys[k] = f"{k}.mtx"
    keys.update(dofs=list(blade.dofs), left=[blade.dofs[i] for i in blade.left],
                right=[blade.dofs[i] for i in blade.right], forced=blade.dofs[blade.forced],
                response=blade.dofs[blade.response])
    return keys


# ------------------------------------------------------------------ reduction
def craig_bampton(M, K, boundary, modes: int):
    """Craig-Bampton reduction onto ``boundary`` DOFs + ``modes`` fixed-interface modes.

    Parameters
    ----------
    M, K : (N, N) symmetric arrays or sparse matrices (FE mass, stiffness)
    boundary : (n_b,) int      retained physical DOFs
    modes : int                fixed-interface normal modes kept

    Returns
    -------
    M_r, K_r : (n_b + modes, n_b + modes) arrays; reduced q = [u_b, eta]
    T : (N, n_b + modes) array; u = T q (static constraint modes, then the
        mass-normalised fixed-interface modes)
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    M, K = sp.csc_matrix(M), sp.csc_matrix(K)
    N = K.shape[0]
    b = np.asarray(boundary, dtype=int)
    inner = np.setdiff1d(np.arange(N), b)
    Kii, Kib, Mii = K[inner][:, inner], K[inner][:, b], M[inner][:, inner]
    lu = spla.splu(Kii.tocsc())
    Psi = -lu.solve(Kib.toarray())  # static constraint modes (N_i, n_b)
    T = np.zeros((N, b.size + modes))
    T[b, np.arange(b.size)] = 1.0
    T[inner, :b.size] = Psi
    if modes:
        # fixed-interface modes: shift-invert about 0 (lowest first)
        w2, Phi = spla.eigsh(Kii, k=modes, M=Mii, sigma=0.0, which="LM")
        order = np.argsort(w2)
        Phi = Phi[:, order]
        Phi /= np.sqrt(np.einsum("ij,ij->j", Phi, Mii @ Phi))
        T[inner, b.size:] = Phi
    Mr, Kr = T.T @ (M @ T), T.T @ (K @ T)
    return 0.5 * (Mr + Mr.T), 0.5 * (Kr + Kr.T), T


def generalized_eigenfrequencies(M, K, count: int) -> np.ndarray:
    """Lowest ``count`` natural frequencies [Hz] of dense (M, K)."""
    import scipy.linalg as sla  # here: the forced response never loads it

    w2 = sla.eigh(np.asarray(K), np.asarray(M), eigvals_only=True, subset_by_index=[0, count - 1])
    return np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)

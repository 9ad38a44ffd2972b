"""Bring your own bodies: condense stiffness matrices exported from another FE code.

This is how the thesis worked (ANSYS matrices, Appendix A.1.1). Per body:

* a stiffness matrix, Matrix Market ``.mtx`` or scipy ``.npz`` (``save_npz``),
  shape (3N, 3N), DOFs node-major: dof = 3 * node + (0, 1, 2 for x, y, z);
* a node file ``.npz`` with ``coords`` (N, 3) [m], ``contact`` (n,) node indices
  of the potential contact nodes and ``distant`` (k,) nodes of the distant face
  (clamped: the rigid motion is imposed there); optional ``sym_x0``, ``sym_y0``
  (nodes on symmetry planes) with ``symmetry`` ("full", "half": y >= 0,
  "quarter": x, y >= 0), ``h`` (n,) initial gap [m] (default: z1 - z2 of the
  contact nodes) and ``area`` (n,) tributary areas [m^2] (default: from the
  tensor grid of the contact nodes, required if they do not form one).

Body 1 lies above body 2 (z up); ``contact[k]`` of both bodies must share x-y.
Everything inconsistent raises ValueError with the reason.
"""
from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.io
import scipy.sparse as sp

from . import linsolve
from .cache import make_key, resolve
from .condense import tributary
from .condensed import CondensedContact, ContactGrid
from .fileio import check_matrix_market, open_npz

SYMMETRIES = {"full": 1.0, "half": 2.0, "quarter": 4.0}
#: Relative asymmetry of an imported stiffness matrix that is still accepted.
SYM_RTOL = 1e-8
#: Contact nodes of the two bodies coincide in x-y within this share of the zone size.
MATCH_RTOL = 1e-6


def load_matrix(path: str | Path) -> sp.csr_matrix:
    """A stiffness matrix from ``.mtx`` or ``.npz``; ValueError if unreadable or not square."""
    path = Path(path)
    if path.suffix == ".mtx":
        check_matrix_market(path, dense=False, what="stiffness file")
        K = scipy.io.mmread(str(path))
    elif path.suffix == ".npz":
        with open_npz(path, "stiffness file") as data:   # sizes checked; scipy reads the same members
            if "format" not in data.files:
                raise ValueError(f"{path}: not a scipy sparse .npz (scipy.sparse.save_npz writes one)")
        K = sp.load_npz(path)
    else:
        raise ValueError(f"{path}: stiffness must be a Matrix Market .mtx or a scipy .npz file")
    K = sp.csr_matrix(K, dtype=float)
    if K.shape[0] != K.shape[1]:
        raise ValueError(f"{path}: stiffness matrix is not square {K.shape}")
    return K


def load_nodes(path: str | Path) -> dict:
    """The node file as a dict of arrays; ValueError for missing entries."""
    with open_npz(path, "node file") as data:
        nodes = {k: data[k] for k in data.files}
    for key in ("coords", "contact", "distant"):
        if key not in nodes:
            raise ValueError(f"{path}: node file lacks '{key}'")
    return nodes


def _check_body(K: sp.csr_matrix, nodes: dict, name: str) -> None:
    X = np.asarray(nodes["coords"], float)
    if X.ndim != 2 or X.shape[1] != 3 or not np.all(np.isfinite(X)):
        raise ValueError(f"{name}: coords must be a finite (N, 3) array")
    if K.shape[0] != 3 * X.shape[0]:
        raise ValueError(f"{name}: stiffness has {K.shape[0]} DOFs but there are {X.shape[0]} nodes "
                         f"(expected 3 per node)")
    if not np.all(np.isfinite(K.data)):
        raise ValueError(f"{name}: stiffness has non-finite entries")
    asym = abs(K - K.T).max() if K.nnz else 0.0
    if asym > SYM_RTOL * abs(K).max():
        raise ValueError(f"{name}: stiffness is not symmetric (max |K - K'| = {asym:.3g})")
    for key in ("contact", "distant", "sym_x0", "sym_y0"):
        idx = np.asarray(nodes.get(key, np.empty(0, int)))
        if idx.size and (idx.dtype.kind not in "iu" or idx.min() < 0 or idx.max() >= X.shape[0]):
            raise ValueError(f"{name}: '{key}' holds invalid node indices")
    if np.asarray(nodes["distant"]).size == 0:
        raise ValueError(f"{name}: the distant face is empty (the body would float)")
    if np.intersect1d(nodes["contact"], nodes["distant"]).size:
        raise ValueError(f"{name}: contact and distant nodes overlap")


def _grid(n1: dict, n2: dict, symmetry: str) -> ContactGrid:
    X1, X2 = n1["coords"][n1["contact"]], n2["coords"][n2["contact"]]
    if X1.shape != X2.shape:
        raise ValueError(f"the bodies have different numbers of contact nodes ({len(X1)} vs {len(X2)})")
    size = max(np.ptp(X2[:, 0]), np.ptp(X2[:, 1]), 1e-300)
    if np.abs(X1[:, :2] - X2[:, :2]).max() > MATCH_RTOL * size:
        raise ValueError("contact nodes of the two bodies do not share x-y positions (hard points)")
    x, y = X2[:, 0], X2[:, 1]
    h = np.asarray(n2.get("h", X1[:, 2] - X2[:, 2]), float)
    if h.shape != x.shape or h.min() < -MATCH_RTOL * size:
        raise ValueError("initial gap h must be (n,) and non-negative (body 1 above body 2)")
    area = n2.get("area")
    if area is None:
        ux, uy = np.unique(x), np.unique(y)
        if ux.size * uy.size != x.size:
            raise ValueError("contact nodes are not a tensor grid: give 'area' in the node file")
        tx = dict(zip(ux, tributary(ux)))
        ty = dict(zip(uy, tributary(uy)))
        area = np.array([tx[a] * ty[b] for a, b in zip(x, y)])
    tol = 1e-9 * size
    copies = np.ones(x.size, int)
    if symmetry in ("half", "quarter"):
        copies *= 1 + (np.abs(y) > tol)
    if symmetry == "quarter":
        copies *= 1 + (np.abs(x) > tol)
    return ContactGrid(x=x, y=y, area=np.asarray(area, float), h=np.maximum(h, 0.0),
                       mult=np.full(x.size, SYMMETRIES[symmetry]), copies=copies)


def _compliance(K, nodes, symmetry, direction="z"):
    fixed = [3 * np.asarray(nodes["distant"]) + c for c in range(3)]
    if symmetry in ("half", "quarter"):
        fixed.append(3 * np.asarray(nodes.get("sym_y0", np.empty(0, int))) + 1)
    if symmetry == "quarter":
        comps = (0,) if direction == "z" else (1, 2)
        fixed += [3 * np.asarray(nodes.get("sym_x0", np.empty(0, int))) + c for c in comps]
    free = np.setdiff1d(np.arange(K.shape[0]), np.concatenate(fixed))
    local = np.full(K.shape[0], -1)
    local[free] = np.arange(free.size)
    dofs = local[3 * np.asarray(nodes["contact"]) + "xyz".index(direction)]
    try:
        return linsolve.compliance_block(K[free][:, free], dofs)
    except Exception as err:  # CHOLMOD: CholmodNotPositiveDefiniteError; SuperLU: RuntimeError
        raise ValueError(f"stiffness is singular or not positive definite with the distant "
                         f"face clamped ({err})") from err


def condense_bodies(K1, nodes1, K2, nodes2, directions=("z",), cache=None) -> CondensedContact:
    """CondensedContact of two imported bodies (see the module docstring)."""
    sym = str(nodes2.get("symmetry", "full"))
    if sym not in SYMMETRIES:
        raise ValueError(f"symmetry must be one of {tuple(SYMMETRIES)}, got {sym!r}")
    for K, nodes, name in ((K1, nodes1, "body 1"), (K2, nodes2, "body 2")):
        _check_body(K, nodes, name)
    grid = _grid(nodes1, nodes2, sym)
    digest = hashlib.sha256()
    for K, nodes in ((K1, nodes1), (K2, nodes2)):
        for arr in (K.indptr, K.indices, K.data, *[np.asarray(nodes[k]) for k in sorted(nodes)]):
            digest.update(np.ascontiguousarray(arr).tobytes())
    key = make_key("byo", digest.hexdigest(), sorted(directions))
    store = resolve(cache)
    hit = store.get(key) if store is not None else None
    t0 = time.perf_counter()
    if hit is None:
        arrays = {}
        for d in sorted(set(directions) | {"z"}):
            for i, (K, nodes) in enumerate(((K1, nodes1), (K2, nodes2)), start=1):
                arrays[f"C{d}{d}_{i}"] = _compliance(K, nodes, sym, d)
        if store is not None:
            store.put(key, arrays, {"byo": True})
    else:
        arrays = hit[0]
    z = (arrays["Czz_1"], arrays["Czz_2"])
    x = (arrays["Cxx_1"], arrays["Cxx_2"]) if "Cxx_1" in arrays else None
    meta = {"symmetry": sym, "byo": True, "timings": {"condensation": time.perf_counter() - t0},
            "cache": {"key": key, "hit": hit is not None}, "solver": linsolve.backend()}
    return CondensedContact(grid=grid, Czz=z[0] + z[1], rigid=np.ones((grid.n, 1)), Czz_bodies=z,
                            Cxx=None if x is None else x[0] + x[1], Cxx_bodies=x, meta=meta)


def export_body(body, K: sp.spmatrix, stiffness_path, nodes_path, symmetry: str, h=None) -> None:
    """Write a built-in ``mesh.BodyMesh`` and its stiffness in the import format."""
    import io

    from .fileio import atomic_write

    stiffness_path = Path(stiffness_path)
    if stiffness_path.suffix == ".mtx":
        buf = io.BytesIO()
        scipy.io.mmwrite(buf, sp.coo_matrix(K), symmetry="general")
        atomic_write(stiffness_path, buf.getvalue())
    else:
        buf = io.BytesIO()
        sp.save_npz(buf, sp.csr_matrix(K))
        atomic_write(stiffness_path, buf.getvalue())
    arrays = {"coords": body.p.T, "contact": body.contact, "distant": body.distant,
              "sym_x0": body.sym_x0, "sym_y0": body.sym_y0, "symmetry": np.array(symmetry)}
    if h is not None:
        arrays["h"] = np.asarray(h)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    atomic_write(nodes_path, buf.getvalue())


@dataclass(frozen=True)
class ImportedBodies:
    """The body kind "imported matrices": a pair of bodies whose geometry lives in files.

    Unlike the built-in kinds (``contact_core.bodies``) it is not meshed here;
    the contact-size estimators of its report come from the named ``summary``
    kind (the geometry the matrices describe, e.g. "sphere").

    Attributes
    ----------
    K1, K2 : scipy.sparse matrix, shape (3 N_i, 3 N_i)   stiffness of body 1 / 2
    nodes1, nodes2 : dict                                 node files (module docstring)
    """

    K1: sp.csr_matrix
    nodes1: dict
    K2: sp.csr_matrix
    nodes2: dict

    @classmethod
    def from_files(cls, stiffness, nodes) -> ImportedBodies:
        """Read two stiffness files and two node files (each a pair of paths)."""
        if not (stiffness and nodes) or len(stiffness) != 2 or len(nodes) != 2:
            raise ValueError("--stiffness and --nodes go together (two files each)")
        K1, K2 = (load_matrix(p) for p in stiffness)
        n1, n2 = (load_nodes(p) for p in nodes)
        return cls(K1, n1, K2, n2)

    def condense(self, directions=("z",), cache=None) -> CondensedContact:
        """The condensed contact (see ``condense_bodies``)."""
        return condense_bodies(self.K1, self.nodes1, self.K2, self.nodes2, directions, cache)


def run_from_files(stiffness, nodes, body: str, force=None, approach=None, cache=None) -> dict:
    """Condense imported bodies, solve one normal load case and summarise it.

    Parameters
    ----------
    stiffness, nodes : pair of paths
        Stiffness matrices and node files of body 1 and body 2.
    body : str
        Body kind whose contact-size estimators the summary uses.
    force, approach : float
        Exactly one: normal force [N] or approach [m].
    cache : see ``contact_core.condense.condense``
    """
    from . import api, report

    cc = ImportedBodies.from_files(stiffness, nodes).condense(cache=cache)
    sol = api.solve(cc, force, approach)
    out = report.summarize(cc, sol, body)
    out["maps"] = report.maps(cc, sol)
    out["timings"] = cc.meta["timings"]
    out["meta"] = {k: cc.meta[k] for k in ("symmetry", "byo", "cache", "solver")}
    return out

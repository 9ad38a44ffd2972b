"""Static (Guyan) condensation of the two FE bodies onto their contact nodes.

With the distant face of each body clamped (its rigid motion imposed, thesis
Appendix A.1.2) the condensed contact compliance of a body is the block of
K_ff^-1 on the contact DOFs (K_ff: stiffness on the free DOFs). Its z-z block
with the tangential contact DOFs left free and unloaded is exactly the inverse of
the thesis's reduced stiffness K~zz (eqs A.10-A.11), so no stiffness inverse is
ever formed: one sparse Cholesky factorisation per body and direction, one block
of unit right-hand sides per contact node (``linsolve.compliance_block``).

Symmetry (quarter model for sphere and cylinder, half model for the flat face):

* z (normal) load, even in x and y: u_x = 0 on x = 0, u_y = 0 on y = 0.
* x (tangential) load: u_x even in x, so u_y, u_z odd in x -> u_y = u_z = 0 on
  x = 0; even in y -> u_y = 0 on y = 0.
* y (tangential) load: u_y even in y, so u_x, u_z odd in y -> u_x = u_z = 0 on
  y = 0; even in x -> u_x = 0 on x = 0.

The rigid motion of a distant face carries the unloaded body with it, so the
closing of the gap per unit approach is 1 at every contact node, and per unit
rotation theta about the y axis (flat face) it is x.
"""
from __future__ import annotations

import hashlib
import time
from pathlib import Path

import numpy as np

from . import assembly, linsolve, mesh
from .cache import entry_path, make_key, resolve
from .condensed import CondensedContact, ContactGrid
from .spec import ContactSpec

_SOURCES = ("mesh.py", "bodies.py", "assembly.py", "condense.py", "spec.py", "linsolve.py")
DIRECTIONS = ("z", "x", "y")
#: Largest Poisson ratio the FE bodies take. Trilinear hexahedra with full integration
#: lock (grow too stiff) towards incompressibility: a sphere's approach at 100 N, grid 15,
#: is 0.9 % below Hertz at nu 0.3, 2.7 % at 0.45, 8 % at 0.49 and 59 % at 0.4999.
MAX_FE_NU = 0.45


def code_version() -> str:
    """Hash of the sources that shape the condensed matrices (part of the cache key)."""
    h = hashlib.sha256()
    for name in _SOURCES:
        h.update((Path(__file__).parent / name).read_bytes())
    return h.hexdigest()[:16]


def _fixed_dofs(body: mesh.BodyMesh, direction: str, symmetry: str) -> np.ndarray:
    """Clamped DOFs (distant face) plus the symmetry conditions of the load direction."""
    fixed = [3 * body.distant + c for c in range(3)]
    on_y0 = (0, 2) if direction == "y" else (1,)     # components odd in y (module docstring)
    fixed += [3 * body.sym_y0 + c for c in on_y0]
    if symmetry == "quarter":
        on_x0 = (1, 2) if direction == "x" else (0,)  # components odd in x
        fixed += [3 * body.sym_x0 + c for c in on_x0]
    return np.unique(np.concatenate(fixed))


def body_compliance(K, body: mesh.BodyMesh, direction: str, symmetry: str,
                    probes: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Compliance (n, n) [m/N] of one body at its contact nodes in ``direction``.

    With ``probes``, also the displacement of the probe nodes per unit contact
    force, shape (n_probe, n), returned as the second item.
    """
    ndof = K.shape[0]
    free = np.setdiff1d(np.arange(ndof), _fixed_dofs(body, direction, symmetry))
    local = np.full(ndof, -1)
    local[free] = np.arange(free.size)
    comp = "xyz".index(direction)
    dofs = local[3 * body.contact + comp]
    if np.any(dofs < 0):
        raise ValueError("a contact DOF is constrained: the contact zone touches a clamped face")
    n = dofs.size
    extra = local[3 * body.probe + comp] if probes else np.empty(0, dtype=int)
    order = None
    if body.shape is not None:  # fill-reducing order from the block structure
        nodes = mesh.nd_order(body.shape)
        order = local[(3 * nodes[:, None] + np.arange(3)).ravel()]
        order = order[order >= 0]
    C = linsolve.compliance_block(K[free][:, free], np.concatenate([dofs, extra]), order)
    return (C[:n, :n], C[n:, :n]) if probes else C


def tributary(u: np.ndarray) -> np.ndarray:
    """1D tributary lengths of sorted zone nodes u; the end nodes own half a cell
    inside the zone (on a symmetry plane: the half inside the modelled part)."""
    mid = 0.5 * (u[1:] + u[:-1])
    lo = np.concatenate([[u[0]], mid])
    hi = np.concatenate([mid, [u[-1]]])
    return hi - lo


def make_grid(spec: ContactSpec, b1: mesh.BodyMesh, b2: mesh.BodyMesh, symmetry: str) -> ContactGrid:
    """Contact grid (positions, areas, weights, initial gap) of the modelled part."""
    x, y = b2.p[0, b2.contact], b2.p[1, b2.contact]
    ux, uy = np.unique(x), np.unique(y)
    area = np.outer(tributary(ux), tributary(uy)).ravel()
    h = spec.kind.gap(spec, b1, b2, x, y)
    tol = 1e-9 * (ux[1] - ux[0])
    copies = 1 + (np.abs(y) > tol).astype(int)
    if symmetry == "quarter":
        copies *= 1 + (np.abs(x) > tol).astype(int)
    weight = 4.0 if symmetry == "quarter" else 2.0
    return ContactGrid(x=x, y=y, area=area, mult=np.full(x.size, weight), h=h, copies=copies)


#: Arrays every direction's cache entry carries (the contact grid; cheap to store twice).
GRID_ARRAYS = ("x", "y", "area", "mult", "h", "copies", "rigid")


def _blocks(direction: str) -> tuple:
    """Names of the arrays that belong to one direction's cache entry (besides the grid)."""
    return (f"C{direction}{direction}_1", f"C{direction}{direction}_2") + (
        ("probe_C1", "probe_x") if direction == "z" else ())


def _build(spec: ContactSpec, directions: tuple, progress=None) -> tuple[dict, dict]:
    """Run the FE stages for ``directions`` only; return the arrays and meta.

    ``progress(done, total, label)`` is called after the mesh, each body's
    assembly and each body's condensation in each direction (None: no calls).
    """
    timings = {"mesh": 0.0, "assembly": 0.0, "condensation": 0.0}
    total, done = 1 + 2 * (1 + len(directions)), 0

    def step(label):
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total, label)

    t0 = time.perf_counter()
    b1, b2, meta = mesh.build(spec)
    timings["mesh"] = time.perf_counter() - t0
    step("mesh")
    sym = meta["symmetry"]
    grid = make_grid(spec, b1, b2, sym)
    arrays = {"x": grid.x, "y": grid.y, "area": grid.area, "mult": grid.mult, "h": grid.h,
              "copies": grid.copies}
    mats = ((spec.E1, spec.nu1), (spec.E2, spec.nu2))
    dofs = []
    for ib, (body, (E, nu)) in enumerate(zip((b1, b2), mats), start=1):
        t0 = time.perf_counter()
        K = assembly.stiffness(body.p, body.t, E, nu)
        timings["assembly"] += time.perf_counter() - t0
        step(f"assembly body {ib}")
        dofs.append(K.shape[0])
        for d in directions:
            t0 = time.perf_counter()
            if d == "z" and ib == 1 and body.probe.size:
                arrays["Czz_1"], arrays["probe_C1"] = body_compliance(K, body, d, sym, probes=True)
                arrays["probe_x"] = body.p[0, body.probe]
            else:
                arrays[f"C{d}{d}_{ib}"] = body_compliance(K, body, d, sym)
            timings["condensation"] += time.perf_counter() - t0
            step(f"condensation body {ib} {d}")
        del K
    arrays["rigid"] = spec.kind.rigid(grid.x)
    meta.update({"spec": spec.key_dict(), "directions": list(directions), "dofs": dofs,
                 "solver": linsolve.backend(), "timings": timings})
    return arrays, meta


def _assemble_result(arrays: dict, meta: dict) -> CondensedContact:
    grid = ContactGrid(x=arrays["x"], y=arrays["y"], area=arrays["area"], mult=arrays["mult"],
                       h=arrays["h"], copies=arrays["copies"])
    z = (arrays["Czz_1"], arrays["Czz_2"])
    x = (arrays["Cxx_1"], arrays["Cxx_2"]) if "Cxx_1" in arrays else None
    y = (arrays["Cyy_1"], arrays["Cyy_2"]) if "Cyy_1" in arrays else None
    return CondensedContact(grid=grid, Czz=z[0] + z[1], rigid=arrays["rigid"], Czz_bodies=z,
                            Cxx=None if x is None else x[0] + x[1], Cxx_bodies=x, meta=meta,
                            probe_x=arrays.get("probe_x"), probe_C1=arrays.get("probe_C1"),
                            Cyy=None if y is None else y[0] + y[1], Cyy_bodies=y)


def check_fe_materials(spec: ContactSpec) -> None:
    """Raise ValueError for a Poisson ratio above :data:`MAX_FE_NU` (volumetric locking)."""
    for name in ("nu1", "nu2"):
        nu = getattr(spec, name)
        if nu > MAX_FE_NU:
            raise ValueError(f"{name} = {nu:g} is above {MAX_FE_NU:g}, where the FE bodies' hexahedra lock "
                             "(the approach comes out 8 % short at 0.49, 59 % at 0.4999): use a Poisson ratio "
                             "of at most 0.45, or the half-space BEM (damper tangential --model bem)")


def direction_key(spec: ContactSpec, direction: str) -> str:
    """Cache key of one direction's compliance blocks of ``spec`` (each direction is its own
    entry, so a tangential run after a normal run on the same bodies builds only x)."""
    return make_key(spec.key_dict(), direction, code_version())


def condense(spec: ContactSpec, directions=("z",), cache=None, progress=None) -> CondensedContact:
    """Condensed contact compliance of the pair ``spec``.

    Parameters
    ----------
    spec : ContactSpec
    directions : sequence of {"z", "x", "y"}
        Compliance blocks to compute; "z" is always included (the normal solve);
        "y" (the second tangential direction) is needed by the contact surface of
        the harmonic balance only.
    cache : None, False, str, Path or a ``cache.CondensationCache``
        None: the default cache folder (``DAMPER_CACHE_DIR`` or ``.damper_cache``);
        False: no cache; a folder: a DiskCache there; an object with
        ``get``/``put`` (e.g. the application's content-addressed store): that.
        Each direction is stored under its own key (``direction_key``); only the
        directions missing from the cache are built (the mesh and assembly are
        redone for them, the cached blocks are loaded).
    progress : callable(done, total, label) or None
        Called after each FE step (mesh, assembly and condensation per body and
        direction) when something is built; None: no calls.

    Returns
    -------
    CondensedContact
        ``meta["timings"]`` holds the seconds per stage (mesh, assembly,
        condensation; ``cache_load`` when blocks were loaded); ``meta["cache"]``:
        ``keys`` and ``hits`` per direction (``keys`` are the store entries),
        ``hit`` (every direction came from the cache), ``key`` (one hash of the
        per-direction keys, naming the combination) and ``paths`` per direction.
    """
    check_fe_materials(spec)
    bad = set(directions) - set(DIRECTIONS)
    if bad:
        raise ValueError(f"unknown direction(s) {sorted(bad)}; use 'z', 'x' and/or 'y'")
    directions = tuple(d for d in DIRECTIONS if d in set(directions) | {"z"})
    store = resolve(cache)
    keys = {d: direction_key(spec, d) for d in directions}
    t0 = time.perf_counter()
    found = {d: store.get(keys[d]) if store is not None else None for d in directions}
    load_time = time.perf_counter() - t0
    missing = tuple(d for d in directions if found[d] is None)
    arrays, meta = {}, None
    for d in directions:                     # cached blocks first (DIRECTIONS order: z, x, y)
        if found[d] is not None:
            arrays.update(found[d][0])
            meta = meta or found[d][1]
    if missing:
        built, meta = _build(spec, missing, progress)
        arrays.update(built)                 # the grid is rebuilt identically (deterministic)
        if store is not None:
            for d in missing:
                names = GRID_ARRAYS + tuple(n for n in _blocks(d) if n in built)
                store.put(keys[d], {n: built[n] for n in names}, meta | {"directions": [d]})
        if len(missing) < len(directions):
            meta["timings"]["cache_load"] = load_time
    else:
        meta["build_timings"] = meta.get("timings")
        meta["timings"] = {"cache_load": load_time}
    meta["directions"] = list(directions)
    meta["cache"] = {"key": make_key(keys), "keys": keys,
                     "hits": {d: found[d] is not None for d in directions},
                     "hit": not missing,
                     "paths": {d: None if store is None else entry_path(store, keys[d])
                               for d in directions}}
    return _assemble_result(arrays, meta)

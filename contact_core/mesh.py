"""Structured, graded hexahedral meshes of the two bodies (thesis section 2.1).

Every body is a logically structured block of trilinear hexahedra, node (i, j, k)
at ``X[i, j, k]``, mapped where needed onto the real geometry. The potential
contact faces of both bodies carry nodes at the same x-y positions (the thesis's
"hard points projection", Appendix B.1.2): a uniform grid of spacing s over the
potential contact zone, then element sizes growing by the grading ratio q.

Body 1 (curved body or damper face) lies above z = 0 (real geometry: above the
surface z_s(x, y) >= 0), body 2 (the plane) below. Symmetry: a quarter model
(x >= 0, y >= 0) for the sphere and the cylinder, a half model (y >= 0) for the
flat face. Element local node order is scikit-fem's ``MeshHex``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # the spec names its body kind, which builds through this module
    from .spec import ContactSpec


#: scikit-fem MeshHex local vertex offsets (i, j, k) of the 8 nodes.
HEX_OFFSETS = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [1, 0, 0],
                        [0, 1, 1], [1, 0, 1], [1, 1, 0], [1, 1, 1]])
#: Largest angular step [rad] along a curved surface, so the polygonal surface
#: stays within 0.9 % of the arc (far from the contact; sphere 41x41: approach
#: -1.96 % -> -1.99 % vs Hertz, a and p0 unchanged, 25 % fewer DOF than pi/24).
MAX_ARC_STEP = math.pi / 12
#: Layers below (above) the contact face graded gently, down to NEAR_DEPTH times
#: the zone half-width: the peak pressure is set by the first layers (measured,
#: sphere 21x21: ratio 1.45 everywhere gave p0 +0.63 %, 8 layers at 1.1 then a
#: faster growth -0.03 %).
NEAR_DEPTH = 1.1
NEAR_RATIO = 1.1
#: Lateral grading: LATERAL_NEAR steps at the grading ratio, then FAR_RATIO
#: (measured, sphere 41x41: a and p0 unchanged to 0.01 %, 20 % fewer DOF).
LATERAL_NEAR = 3
FAR_RATIO = 2.0
#: Box side (in nodes) below which nested dissection stops splitting.
ND_LEAF = 6
#: Most modelled contact nodes accepted: the dense compliances are n x n
#: (4000: 128 MB each, a few of them alive at once).
MAX_CONTACT_NODES = 4000
#: Extra growth ratio of the deeper layers over the lateral grading ratio.
DEEP_EXTRA = 0.15


@dataclass(frozen=True)
class BodyMesh:
    """A meshed body.

    Attributes
    ----------
    p : ndarray, shape (3, N)   node coordinates [m]
    t : ndarray, shape (8, nel) element connectivity (scikit-fem order)
    contact : ndarray, shape (n,)  node index of each contact-grid node
    distant : ndarray        nodes of the distant face (clamped: rigid motion imposed)
    sym_x0, sym_y0 : ndarray nodes on the symmetry planes x = 0 and y = 0
    probe : ndarray          free surface nodes on the row y = 0 beyond the zone
                             (quarter models): where the thesis measures the
                             body's compression outside the contact (section 2.2.5)
    shape : tuple (nx, ny, nz) logical size of the structured block (node
                             (i, j, k) has index (i ny + j) nz + k)
    """

    p: np.ndarray
    t: np.ndarray
    contact: np.ndarray
    distant: np.ndarray
    sym_x0: np.ndarray
    sym_y0: np.ndarray
    probe: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=int))
    shape: tuple | None = None


def graded(start: float, end: float, s0: float, q: float, cap: float = np.inf,
           far: float = FAR_RATIO) -> np.ndarray:
    """Points after ``start`` up to ``end`` with steps s0*q, s0*q^2, ... (capped),
    growing by FAR_RATIO after LATERAL_NEAR steps.

    The steps are scaled by one common factor so that the last point is ``end``.
    Returns shape (m,), excluding ``start``; empty if ``end <= start``.
    """
    span = end - start
    if span <= 1e-12 * max(abs(end), 1.0):
        return np.empty(0)
    steps, step, total = [], s0, 0.0
    while total < span * (1.0 - 1e-9):
        step = min(step * (q if len(steps) < LATERAL_NEAR else max(q, far)), cap)
        steps.append(step)
        total += step
    steps = np.asarray(steps) * (span / total)
    return start + np.cumsum(steps)


def depth_levels(span: float, s0: float, q: float, near: float) -> np.ndarray:
    """Levels 0 < z <= span away from the contact face: steps growing by NEAR_RATIO
    from s0 down to the depth ``near``, then by q + DEEP_EXTRA; scaled so the last
    level is span."""
    steps, step, total = [], s0 / NEAR_RATIO, 0.0
    while total < span * (1.0 - 1e-9):
        step *= NEAR_RATIO if total < near else q + DEEP_EXTRA
        steps.append(step)
        total += step
    return np.cumsum(steps) * (span / total)


def zone_points(extent: float, n_side: int, symmetric_half: bool) -> np.ndarray:
    """Uniform contact-zone coordinates: [0, extent] (quarter/half axis, n_side odd
    nodes over [-extent, extent] in the full model) or the full [-extent, extent]."""
    full = np.linspace(-extent, extent, n_side)
    full[n_side // 2] = 0.0  # exactly on the symmetry plane
    return full[full >= -1e-15 * extent] if symmetric_half else full


def _arc_points(x_zone: np.ndarray, R: float, q: float) -> np.ndarray:
    """Zone points, then points x = R sin(theta) graded in theta up to the rim x = R."""
    s = x_zone[1] - x_zone[0]
    th0 = math.asin(min(x_zone[-1] / R, 1.0))
    th = graded(th0, 0.5 * math.pi, s / R, q, MAX_ARC_STEP)
    return np.concatenate([x_zone, R * np.sin(th)])


def structured(X: np.ndarray, Y: np.ndarray, Z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and hexahedra of a logically structured block.

    Parameters
    ----------
    X, Y, Z : ndarray, shape (nx, ny, nz)
        Node coordinates [m], right-handed in (i, j, k).

    Returns
    -------
    p : ndarray, shape (3, nx*ny*nz); t : ndarray, shape (8, (nx-1)(ny-1)(nz-1))
    """
    nx, ny, nz = X.shape
    idx = np.arange(nx * ny * nz).reshape(nx, ny, nz)
    t = np.stack([idx[o[0]:nx - 1 + o[0], o[1]:ny - 1 + o[1], o[2]:nz - 1 + o[2]].ravel()
                  for o in HEX_OFFSETS])
    return np.stack([X.ravel(), Y.ravel(), Z.ravel()]), t


def _body(X, Y, Z, nzx: int, nzy: int, contact_k: int, distant: np.ndarray) -> BodyMesh:
    """Assemble a BodyMesh; the contact grid is nzx x nzy nodes at level contact_k:
    i < nzx on a quarter model (x >= 0), the nzx lines centred on x = 0 otherwise."""
    p, t = structured(X, Y, Z)
    idx = np.arange(X.size).reshape(X.shape)
    xline = X[:, 0, contact_k]
    ii = np.arange(nzx) if xline[0] >= 0 else _centered(xline, nzx)
    contact = idx[np.ix_(ii, np.arange(nzy), [contact_k])].ravel()
    tol = 1e-12 * np.max(np.abs(p))
    probe = np.empty(0, dtype=int)
    if xline[0] >= 0:
        probe = np.setdiff1d(idx[nzx:, 0, contact_k], distant)
    return BodyMesh(p=p, t=t, contact=contact, distant=distant,
                    sym_x0=np.flatnonzero(np.abs(p[0]) <= tol),
                    sym_y0=np.flatnonzero(np.abs(p[1]) <= tol), probe=probe, shape=X.shape)


def nd_order(shape: tuple, leaf: int = ND_LEAF) -> np.ndarray:
    """Nested-dissection order of the nodes of a structured (nx, ny, nz) hex grid.

    The longest logical side is split at its middle plane, which separates the
    two halves (hexahedra couple neighbouring planes only); the order is [left
    half, right half, plane], recursively: the classic optimal ordering of grid
    graphs, used to give SuperLU a fill-reducing order (METIS-like fill, where
    its own MMD ordering filled 25 % more on a test block).
    """
    idx = np.arange(int(np.prod(shape))).reshape(shape)
    out = []

    def split(lo, hi):
        ext = [h - l for l, h in zip(lo, hi)]
        d = int(np.argmax(ext))
        if ext[d] <= leaf:
            out.append(idx[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]].ravel())
            return
        m = (lo[d] + hi[d]) // 2
        split(lo, hi[:d] + [m] + hi[d + 1:])
        split(lo[:d] + [m + 1] + lo[d + 1:], hi)
        out.append(idx[tuple(slice(m, m + 1) if e == d else slice(lo[e], hi[e]) for e in range(3))].ravel())

    split([0, 0, 0], list(shape))
    return np.concatenate(out)


def _centered(xline: np.ndarray, nzx: int) -> np.ndarray:
    """Indices of the nzx zone nodes centred on x = 0 in a full x-line."""
    c = int(np.argmin(np.abs(xline)))
    return np.arange(c - nzx // 2, c + nzx // 2 + 1)


def plane_block(xs, ys, depth: float, s: float, q: float, nzx: int, nzy: int, near: float) -> BodyMesh:
    """Body 2: the block below z = 0 on x-y lines ``xs``, ``ys``, graded in depth."""
    zs = -depth_levels(depth, s, q, near)[::-1]
    zs = np.concatenate([zs, [0.0]])
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    nz = zs.size
    idx = np.arange(X.size).reshape(X.shape)
    return _body(X, Y, Z, nzx, nzy, nz - 1, idx[:, :, 0].ravel())


def upper_block(xs, ys, height: float, s: float, q: float, nzx: int, nzy: int, near: float) -> BodyMesh:
    """Body 1 as a block above z = 0 (half-space variant, flat face)."""
    zs = np.concatenate([[0.0], depth_levels(height, s, q, near)])
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    idx = np.arange(X.size).reshape(X.shape)
    return _body(X, Y, Z, nzx, nzy, 0, idx[:, :, -1].ravel())


def _lift(X2, Y2, zsurf, R, s, q, near):
    """Columns from the curved surface z_s up to the flat distant face z = R."""
    phi = np.concatenate([[0.0], depth_levels(1.0, s / R, q, near / R)])
    Z = zsurf[:, :, None] + (R - zsurf)[:, :, None] * phi[None, None, :]
    X = np.repeat(X2[:, :, None], phi.size, axis=2)
    Y = np.repeat(Y2[:, :, None], phi.size, axis=2)
    return X, Y, Z


def half_sphere(R: float, xz: np.ndarray, q: float) -> BodyMesh:
    """Quarter of a real half-sphere (radius R, flat face z = R, pole at the origin).

    A graded square [0, R]^2 is mapped onto the quarter disk r <= R: identity in
    the contact zone (so its nodes keep the plane's x-y), blending smoothly into
    the square-to-disk map x = xi * max(xi, eta) / |(xi, eta)| at the rim; then
    each column is lifted from the sphere z_s = R - sqrt(R^2 - r^2) to z = R.
    The rim nodes collapse onto the flat face, where they are clamped anyway.
    """
    xi = _arc_points(xz, R, q)
    XI, ETA = np.meshgrid(xi, xi, indexing="ij")
    m = np.maximum(XI, ETA)
    rho = np.hypot(XI, ETA)
    w = np.clip((m - xz[-1]) / (R - xz[-1]), 0.0, 1.0) ** 2
    g = 1.0 + w * (np.divide(m, rho, out=np.ones_like(m), where=rho > 0) - 1.0)
    X2, Y2 = XI * g, ETA * g
    r2 = np.minimum(X2**2 + Y2**2, R**2)
    X, Y, Z = _lift(X2, Y2, R - np.sqrt(R**2 - r2), R, xz[1] - xz[0], q, NEAR_DEPTH * xz[-1])
    idx = np.arange(X.size).reshape(X.shape)
    distant = np.union1d(idx[:, :, -1].ravel(), np.flatnonzero(Z.ravel() >= R * (1 - 1e-12)))
    return _body(X, Y, Z, xz.size, xz.size, 0, distant)


def half_cylinder(R: float, xz: np.ndarray, ys: np.ndarray, q: float) -> BodyMesh:
    """Quarter of a real half-cylinder (radius R, axis along y at z = R, x >= 0,
    0 <= y <= L/2 on the lines ``ys``), its cut face z = R the distant face."""
    xi = _arc_points(xz, R, q)
    X2, Y2 = np.meshgrid(xi, ys, indexing="ij")
    X, Y, Z = _lift(X2, Y2, R - np.sqrt(np.maximum(R**2 - X2**2, 0.0)), R, xz[1] - xz[0], q,
                    NEAR_DEPTH * xz[-1])
    idx = np.arange(X.size).reshape(X.shape)
    distant = np.union1d(idx[:, :, -1].ravel(), np.flatnonzero(Z.ravel() >= R * (1 - 1e-12)))
    return _body(X, Y, Z, xz.size, ys.size, 0, distant)


def build(spec: ContactSpec) -> tuple[BodyMesh, BodyMesh, dict]:
    """Meshes of body 1 and body 2 for ``spec`` (built by its body kind) and a description."""
    b1, b2, s = spec.kind.meshes(spec)
    if b1.contact.size > MAX_CONTACT_NODES:
        raise ValueError(f"{b1.contact.size} contact nodes exceed {MAX_CONTACT_NODES}: "
                         f"lower --grid (dense compliances grow as n^2)")
    zx, zy = spec.zone()
    meta = {"symmetry": spec.kind.symmetry, "zone": [zx, zy], "spacing": float(s),
            "n_side": spec.n_side, "nodes": [b1.p.shape[1], b2.p.shape[1]],
            "elements": [b1.t.shape[1], b2.t.shape[1]]}
    return b1, b2, meta


def cylinder_lines(zy: float, s: float, n_side: int) -> np.ndarray:
    """Lines along the cylinder, 0 <= y <= L/2: s/2 at the end y = L/2, where the
    edge pressure peak sits, growing by 1.25 towards the middle up to the larger
    of 2 s and (L/2) / n_side (a long cylinder is nearly plane strain there)."""
    cap = max(2.0 * s, zy / n_side)
    d = graded(0.0, zy, s / 2.0, 1.25, cap, far=1.25)      # distances from the end
    return np.concatenate([[0.0], zy - d[::-1][1:], [zy]])

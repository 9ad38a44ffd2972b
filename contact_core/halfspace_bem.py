"""Half-space influence-coefficient (boundary-element) contact model.

A fast, independent oracle for the FE contact models and a fast option for
users: both bodies are elastic half-spaces, the curvature enters only through
the initial gap ``h = r^2 / (2 R)`` (sphere) or ``h = x^2 / (2 R)`` (cylinder
with its axis along y, cut off at its ends ``|y| <= L/2``). It cannot see
finite bodies (their extra compliance, the cylinder's body compression).

The potential contact zone is a regular grid of ``nx * ny`` rectangular cells
of size ``dx * dy``; node i sits at the centre of cell i. A nodal force f_j
[N] is a uniform traction f_j / (dx dy) over cell j, and displacements are
collocated at the nodes. The surface displacement of a half-space (modulus E,
Poisson's ratio nu, shear modulus G = E / (2 (1 + nu))) under a point force at
distance rho = sqrt(X^2 + Y^2) is (Johnson, Contact Mechanics, 1985, ch. 3:
concentrated normal and tangential forces; Love 1929 for the uniformly loaded
rectangle)

    normal force P (Boussinesq):       u_z = (1 - nu^2) / (pi E) * P / rho
    tangential force Q_x (Cerruti):    u_x = Q_x / (2 pi G) * [(1 - nu) / rho + nu X^2 / rho^3]

Integrated over a rectangle these have closed forms (``_rect_inv_rho``,
``_rect_x2_rho3``; checked against quadrature and Love's centre displacement
in tests/contact/test_halfspace_bem.py). The combined (relative) compliance of the pair is the sum
over the two bodies; the coupling of normal and tangential displacements
(Johnson's constant beta) is neglected, exactly so for like materials and as
the thesis does (Appendix A.2, decoupled problems).

Symbols: n number of nodes, E [Pa], nu [-], G [Pa], R radius [m], L cylinder
length [m], C compliance [m/N].
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Default material: steel.
STEEL = (200e9, 0.3)


@dataclass(frozen=True)
class HalfspaceGrid:
    """A regular grid of contact cells (cell-centred nodes).

    Attributes
    ----------
    x, y : ndarray, shape (n,)
        Node (cell centre) coordinates [m], x fastest.
    dx, dy : float
        Cell size [m].
    nx, ny : int
        Cells along x and y.
    """

    x: np.ndarray
    y: np.ndarray
    dx: float
    dy: float
    nx: int
    ny: int

    @property
    def area(self) -> np.ndarray:
        """Cell areas [m^2], shape (n,)."""
        return np.full(self.x.size, self.dx * self.dy)


def regular_grid(half_x: float, half_y: float, nx: int, ny: int) -> HalfspaceGrid:
    """Cells covering ``[-half_x, half_x] x [-half_y, half_y]``; node i at cell centre."""
    for name, v in (("half_x", half_x), ("half_y", half_y)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"halfspace grid: {name} must be positive and finite, got {v}")
    if int(nx) < 3 or int(ny) < 1:
        raise ValueError(f"halfspace grid: need nx >= 3 and ny >= 1 cells, got {nx}, {ny}")
    dx, dy = 2.0 * half_x / nx, 2.0 * half_y / ny
    xc = -half_x + dx * (np.arange(nx) + 0.5)
    yc = -half_y + dy * (np.arange(ny) + 0.5)
    X, Y = np.meshgrid(xc, yc, indexing="xy")
    return HalfspaceGrid(X.ravel(), Y.ravel(), dx, dy, int(nx), int(ny))


def _xlog(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a * asinh(b / |a|)``, continuous with limit 0 at a = 0."""
    out = np.zeros(np.broadcast(a, b).shape)
    nz = a != 0.0
    a_, b_ = np.broadcast_to(a, out.shape)[nz], np.broadcast_to(b, out.shape)[nz]
    out[nz] = a_ * np.arcsinh(b_ / np.abs(a_))
    return out


def _corner_sum(F, X1, X2, Y1, Y2):
    """Double integral over [X1, X2] x [Y1, Y2] from an antiderivative F(X, Y)."""
    return F(X2, Y2) - F(X1, Y2) - F(X2, Y1) + F(X1, Y1)


def _rect_inv_rho(X1, X2, Y1, Y2):
    """Integral of 1/rho over the rectangle [X1, X2] x [Y1, Y2] (rho from the origin).

    Antiderivative X asinh(Y/|X|) + Y asinh(X/|Y|): its mixed derivative is
    1/rho; the terms X ln|X| dropped against the log form cancel between corners.
    """
    return _corner_sum(lambda X, Y: _xlog(X, Y) + _xlog(Y, X), X1, X2, Y1, Y2)


def _rect_x2_rho3(X1, X2, Y1, Y2):
    """Integral of X^2/rho^3 over the rectangle (antiderivative Y asinh(X/|Y|))."""
    return _corner_sum(lambda X, Y: _xlog(Y, X), X1, X2, Y1, Y2)


def offset_kernels(grid: HalfspaceGrid) -> tuple[np.ndarray, np.ndarray]:
    """Kernel integrals over one cell for every index offset between nodes.

    Returns
    -------
    k1, k2 : ndarray, shape (2 ny - 1, 2 nx - 1)
        ``k[dy + ny - 1, dx + nx - 1]``: integral of 1/rho (k1) and of
        X^2/rho^3 (k2) over a cell seen from a node ``dx`` cells along x and
        ``dy`` along y away [m].
    """
    ox = np.arange(-(grid.nx - 1), grid.nx) * grid.dx
    oy = np.arange(-(grid.ny - 1), grid.ny) * grid.dy
    OX, OY = np.meshgrid(ox, oy, indexing="xy")
    hx, hy = 0.5 * grid.dx, 0.5 * grid.dy
    return (_rect_inv_rho(OX - hx, OX + hx, OY - hy, OY + hy),
            _rect_x2_rho3(OX - hx, OX + hx, OY - hy, OY + hy))


def toeplitz(k: np.ndarray, grid: HalfspaceGrid) -> np.ndarray:
    """The (n, n) block-Toeplitz matrix ``M[i, j] = k[offset(i, j)]`` (node i, cell j).

    Gathered block-wise (an (nx, nx) Toeplitz block per y offset), so no (n, n)
    index array is ever formed.
    """
    nx, ny = grid.nx, grid.ny
    ix, iy = np.arange(nx), np.arange(ny)
    blocks = k[:, ix[:, None] - ix[None, :] + nx - 1]          # (2 ny - 1, nx, nx)
    full = blocks[iy[:, None] - iy[None, :] + ny - 1]           # (ny, ny, nx, nx)
    return full.transpose(0, 2, 1, 3).reshape(nx * ny, nx * ny)


def cell_integrals(grid: HalfspaceGrid) -> tuple[np.ndarray, np.ndarray]:
    """Kernel integrals between every node i and every cell j.

    Returns
    -------
    I1, I2 : ndarray, shape (n, n)
        ``I1[i, j]`` = integral over cell j of 1/rho, ``I2[i, j]`` of
        X^2/rho^3, with (X, Y) the vector from the source point to node i [m].
    """
    k1, k2 = offset_kernels(grid)
    return toeplitz(k1, grid), toeplitz(k2, grid)


def body_compliances(I1, I2, area, E: float, nu: float) -> tuple[np.ndarray, np.ndarray]:
    """Normal and tangential-x compliance of one half-space [m/N], shape (n, n).

    ``C[i, j]`` is the displacement at node i per unit nodal force at node j
    (Boussinesq and Cerruti, module docstring), the force spread over cell j.
    """
    if not (np.isfinite(E) and E > 0):
        raise ValueError(f"halfspace: Young's modulus must be positive, got {E}")
    if not (np.isfinite(nu) and -1.0 < nu < 0.5):
        raise ValueError(f"halfspace: Poisson's ratio must be in (-1, 0.5), got {nu}")
    G = E / (2.0 * (1.0 + nu))
    area = np.asarray(area, float)
    per_cell = area[None, :] if area.ndim == 1 else area  # scalar for offset kernels
    Czz = (1.0 - nu**2) / (np.pi * E) * I1 / per_cell
    Cxx = ((1.0 - nu) * I1 + nu * I2) / (2.0 * np.pi * G) / per_cell
    return Czz, Cxx


def gap_sphere(grid: HalfspaceGrid, radius: float) -> np.ndarray:
    """Initial gap h = r^2 / (2 R) of a sphere over a plane [m], shape (n,)."""
    return (grid.x**2 + grid.y**2) / (2.0 * radius)


def gap_cylinder(grid: HalfspaceGrid, radius: float) -> np.ndarray:
    """Initial gap h = x^2 / (2 R) of a cylinder (axis along y) over a plane [m]."""
    return grid.x**2 / (2.0 * radius)


def condense_grid(grid: HalfspaceGrid, h: np.ndarray, materials=(STEEL, STEEL),
                  directions=("z", "x"), meta: dict | None = None):
    """The half-space pair on ``grid`` as a ``CondensedContact`` (full grid, mult = 1).

    Parameters
    ----------
    grid : HalfspaceGrid
        Contact cells.
    h : ndarray, shape (n,)
        Initial gap [m].
    materials : ((E1, nu1), (E2, nu2))
        Body 1 (curved) and body 2 (plane) [Pa, -].
    directions : tuple of str
        ``"x"`` adds the tangential compliance ``Cxx``.
    meta : dict, optional
        Extra metadata (geometry) stored in ``meta``.

    Returns
    -------
    contact_core.condensed.CondensedContact
        ``rigid`` is a column of ones (the approach); no rotation DOF.
    """
    from contact_core.condensed import CondensedContact, ContactGrid

    area = grid.area
    k1, k2 = offset_kernels(grid)
    (E1, nu1), (E2, nu2) = materials
    # compliances are linear in the kernels: combine on the small offset
    # arrays, gather each distinct (n, n) matrix once; like bodies share theirs
    kz1, kx1 = body_compliances(k1, k2, grid.dx * grid.dy, E1, nu1)
    kz2, kx2 = body_compliances(k1, k2, grid.dx * grid.dy, E2, nu2)
    same = (E1, nu1) == (E2, nu2)
    tangential = "x" in directions
    z1 = toeplitz(kz1, grid)
    z2 = z1 if same else toeplitz(kz2, grid)
    x1 = toeplitz(kx1, grid) if tangential else None
    x2 = x1 if same or not tangential else toeplitz(kx2, grid)
    n = grid.x.size
    cgrid = ContactGrid(x=grid.x, y=grid.y, area=area, mult=np.ones(n),
                        h=np.asarray(h, float), copies=np.ones(n, dtype=int))
    info = {"model": "bem", "materials": {"E1": E1, "nu1": nu1, "E2": E2, "nu2": nu2},
            "grid": {"nx": grid.nx, "ny": grid.ny, "dx": grid.dx, "dy": grid.dy,
                     "symmetry": "none"}}
    info.update(meta or {})
    for m in (z1, z2, x1, x2):  # shared between bodies: keep them unmodifiable
        if m is not None:
            m.setflags(write=False)
    return CondensedContact(grid=cgrid, Czz=z1 + z2, rigid=np.ones((n, 1)), Czz_bodies=(z1, z2),
                            Cxx=(x1 + x2) if tangential else None,
                            Cxx_bodies=(x1, x2) if tangential else None, meta=info)


def sphere(radius: float, half_width: float, n: int, materials=(STEEL, STEEL),
           directions=("z", "x")):
    """Sphere (radius R [m]) on a plane: an ``n x n`` grid over ``|x|, |y| <= half_width``."""
    _check_positive(radius=radius, half_width=half_width)
    grid = regular_grid(half_width, half_width, n, n)
    geometry = {"geometry": {"body": "sphere", "radius": float(radius)}}
    return condense_grid(grid, gap_sphere(grid, radius), materials, directions, geometry)


def cylinder(radius: float, length: float, half_width: float, nx: int, ny: int,
             materials=(STEEL, STEEL), directions=("z", "x")):
    """Cylinder (radius R, length L [m], axis along y) on a plane.

    ``nx`` cells over ``|x| <= half_width`` and ``ny`` cells over the length
    ``|y| <= L/2``; the ends of the cylinder are the ends of the grid.
    """
    _check_positive(radius=radius, length=length, half_width=half_width)
    grid = regular_grid(half_width, 0.5 * length, nx, ny)
    geometry = {"geometry": {"body": "cylinder", "radius": float(radius), "length": float(length)}}
    return condense_grid(grid, gap_cylinder(grid, radius), materials, directions, geometry)


def condense(spec, directions=("z", "x")):
    """The half-space model of a ``contact_core.spec.ContactSpec`` (sphere or cylinder).

    Same potential zone (``spec.zone()``) and nodes per side (``spec.n_side``)
    as the FE model, but a full grid (no symmetry, ``mult = 1``) of cells
    centred on the nodes; a drop-in replacement for ``contact_core.condense.condense``.
    """
    import time

    t0 = time.perf_counter()
    cc = spec.kind.bem(spec, directions)   # the body kind knows its grid (sphere, cylinder)
    cc.meta.update({"spec": spec.key_dict() | {"model": "bem"},
                    "timings": {"influence": time.perf_counter() - t0}})
    return cc


def _check_positive(**values) -> None:
    for name, v in values.items():
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"halfspace: {name} must be positive and finite, got {v}")

"""Body kinds: one class per contact geometry (body 1 on the plane, body 2).

Each kind owns what depends on its geometry: the options it needs and their
validation, the potential contact zone, the meshes, the initial gap, the rigid
DOFs of the distant faces, the analytic reference (Hertz / 2D Hertz /
Cattaneo-Mindlin), the contact-size estimators of a solved state and the labels
of its plots. Everything else (condensation, solves, reports, the CLI) asks the
kind, so a new geometry (e.g. an underplatform-damper wedge) is one new
subclass registered with :func:`register`, not edits in a dozen modules.

The kinds are looked up by name (``ContactSpec.body``) through :func:`get`.
Symbols as in ``contact_core.spec`` and ``contact_core.report``; SI units.
"""
from __future__ import annotations

import math

import numpy as np

from . import hertz, mesh
from .tangential_reference import shear_modulus_star

#: A contact narrower than this many grid spacings (radius or half-width) is
#: flagged ``under_resolved``: its size and peak pressure are then rough.
MIN_NODES_ACROSS = 3
#: Distance (in contact radii / half-widths) where the thesis measures a body's
#: compression outside the contact (section 2.2.5: "3b").
FAR_PROBE = 3.0
#: Edge-effect widening of a cylinder's contact at its ends (thesis Fig. 5).
CYLINDER_END_WIDENING = 1.3
#: Largest Hertz contact size (radius a or half-width b) accepted, as a share
#: of the body radius R: Hertz's small-strain, a << R assumptions (and the
#: graded mesh around the zone, which must fit inside the body) fail beyond.
#: Measured: the real half-sphere meshes with a/R = 0.17 and inverts elements at
#: 0.19 (zone 1.15 a), at 7, 21 and 41 nodes per side.
MAX_CONTACT_SHARE = 0.15
#: Smallest Hertz contact radius of a sphere as a share of its radius R: the gap at the
#: contact's edge, a^2 / (2R), is then 4.5e-12 R, a few hundred ulp of the mesh's
#: coordinates (~R). Measured on R = 10 mm steel, halfspace, 5 nodes per side: 1e-9 N
#: (a = 4.5e-6 R) solves, 2e-11 N (a = 1.2e-6 R) puts contact on the zone's edge, 1e-20 N
#: asks for a mesh of 6e7 nodes and an approach of 5e-324 m divides by zero.
MIN_CONTACT_SHARE = 3e-6
#: Largest mean strain of a flat face's contact: mean pressure over E*, or approach over
#: the face's smaller side. The sphere's bound (contact radius <= 0.15 R) is a mean
#: pressure of 0.064 E*; an approach of 1 m on a 1.2 mm face gave 9e13 Pa as a result.
MAX_CONTACT_STRAIN = 0.1
#: Smallest mean strain of a flat face's contact, by force or by approach (the sphere's
#: floor, a contact radius of 3e-6 R, is an approach of 9e-12 R): far below, the forces
#: leave double precision (an approach of 5e-324 m gave a force 1.9 times k_n times it).
MIN_CONTACT_STRAIN = 1e-12


def under_resolved_warning(p_design: str, grid: str) -> str:
    """The warning for a result flagged ``under_resolved``, naming the caller's settings
    (``p_design``, ``grid``: an option or a scene key) that resolve the contact."""
    return (f"warning: under-resolved: the contact spans fewer than {MIN_NODES_ACROSS} grid spacings "
            "(radius or half-width), so its size, peak pressure, approach and k_n are rough (grid 3: k_n 54 % "
            f"below Hertz); lower {p_design} (the potential zone is sized for that peak pressure) or refine {grid}")


_KINDS: dict[str, Body] = {}


def register(kind: Body) -> Body:
    """Make ``kind`` available under ``kind.name`` (returns it, for use as a decorator result)."""
    _KINDS[kind.name] = kind
    return kind


def names() -> tuple[str, ...]:
    """Names of the registered body kinds (CLI choices)."""
    return tuple(_KINDS)


def get(body) -> Body:
    """The kind named ``body`` (a Body instance is returned as is); ValueError if unknown."""
    if isinstance(body, Body):
        return body
    try:
        return _KINDS[body]
    except (KeyError, TypeError):
        raise ValueError(f"body must be one of {names()}, got {body!r}") from None


def fit_edge(u: np.ndarray, p: np.ndarray) -> float:
    """Edge a of p^2 = c (a^2 - u^2) fitted to points (u, p), or nan if < 2 points."""
    if u.size < 2 or np.ptp(u**2) == 0:
        return float("nan")
    slope, icept = np.polyfit(u**2, p**2, 1)
    return float(np.sqrt(icept / -slope)) if slope < 0 < icept else float("nan")


def row_extent(u: np.ndarray, active: np.ndarray, spacing: float) -> float:
    """Outer edge of the contact on a grid row: last active |u| plus half a cell."""
    return float(np.max(np.abs(u[active])) + 0.5 * spacing) if active.any() else 0.0


def share_far(out: dict, cc, sol, size: float) -> None:
    """Body 1's compression outside the contact, u_1o / delta at x ~ 3 b (thesis 2.2.5).

    u_1o is the elastic displacement of body 1's free surface at the probe
    nearest x = FAR_PROBE * size (accepted within 2.5-4 sizes); it excludes
    the local indentation that ``body1_share`` (at the centre) includes.
    """
    if cc.probe_x is None or cc.probe_x.size == 0 or sol.q[0] <= 0:
        return
    i = int(np.argmin(np.abs(cc.probe_x - FAR_PROBE * size)))
    if 2.5 * size <= cc.probe_x[i] <= 4.0 * size:
        out["body1_share_far"] = float(cc.probe_C1[i] @ sol.f / sol.q[0])
        out["body1_share_far_at"] = float(cc.probe_x[i])


#: Largest body dimension [m] (radius, length, width, height): the bodies of a friction
#: contact are millimetres to centimetres; far beyond, the Hertz relations (a^3 / R, the
#: force for a contact radius) leave double precision (R = 1e308 m overflows).
MAX_SIZE = 1e3
#: Smallest body dimension [m]: 1 um, far below a damper's (millimetres); below, the
#: Hertz relations divide by underflowed sizes (R = 1e-300 m: a ZeroDivisionError) and
#: a continuum model of the body no longer holds.
MIN_SIZE = 1e-6


def _positive(name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    if value > MAX_SIZE:
        raise ValueError(f"{name} = {value:.4g} m is above the limit {MAX_SIZE:g} m (a contact body "
                         "of a friction damper is millimetres to centimetres)")
    if value < MIN_SIZE:
        raise ValueError(f"{name} = {value:.4g} m is below the limit {MIN_SIZE:g} m (a contact body "
                         "of a friction damper is millimetres to centimetres)")


def _floor3(x: float) -> float:
    """``x`` > 0 rounded down to three significant digits."""
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.floor(x / step) * step


class Body:
    """Base class of a body kind; subclasses override what their geometry changes.

    Class attributes
    ----------------
    name : str            the ``ContactSpec.body`` value
    required : tuple      geometry fields of ContactSpec that must be positive
    symmetry : str        modelled part: "quarter" (x, y >= 0) or "half" (y >= 0)
    curved : bool         has a real (curved) and a half-space FE variant
    size_key : str|None   report key of the contact size (radius / half-width)
    peak_key : str        report key of the peak pressure compared with the reference
    """

    name = ""
    required: tuple = ()
    symmetry = "quarter"
    curved = True
    size_key: str | None = None
    peak_key = "p_max"
    zone_from_load = False

    # -- options ---------------------------------------------------------------
    def validate(self, spec) -> None:
        """Raise ValueError for missing or bad geometry of ``spec``."""
        for name in self.required:
            _positive(name, getattr(spec, name))
        if spec.height:
            _positive("height", spec.height)
        if spec.load_hint > 0:
            self.check_load(spec, spec.load_hint)

    def check_load(self, spec, force: float) -> None:
        """Refuse a normal force whose contact the model cannot represent (ValueError)."""

    def check_eccentricity(self, spec, eccentricity) -> None:
        """Refuse a normal-load eccentricity the kind cannot carry (only a flat face can)."""
        if eccentricity:
            raise ValueError("eccentricity applies to the flat face only")

    def key_model(self, spec) -> str:
        """The FE variant that defines the model (for the cache key)."""
        return spec.model

    # -- model -----------------------------------------------------------------
    def zone(self, spec) -> tuple[float, float]:
        """Half-extents (zx, zy) [m] of the potential contact zone of the full model."""
        raise NotImplementedError

    def meshes(self, spec) -> tuple:
        """(body 1, body 2, grid spacing s [m]) meshes of the modelled part."""
        raise NotImplementedError

    def gap(self, spec, b1, b2, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Initial gap h (n,) [m] at the contact nodes."""
        if spec.model == "real" and self.curved:
            return b1.p[2, b1.contact] - b2.p[2, b2.contact]   # the true surface z_s(x, y)
        return self.halfspace_gap(spec, x, y)

    def halfspace_gap(self, spec, x, y) -> np.ndarray:
        """Gap of the curvature alone (half-space variant)."""
        return np.zeros_like(x)

    def rigid(self, x: np.ndarray) -> np.ndarray:
        """Closing (n, r) per rigid DOF of the distant faces: the approach only."""
        return np.ones((x.size, 1))

    def bem(self, spec, directions):
        """The half-space influence-coefficient model (``halfspace_bem``) of ``spec``."""
        raise ValueError(f"the half-space BEM model handles sphere and cylinder, not {self.name!r}")

    # -- references and results ---------------------------------------------------
    def reference(self, spec, force: float) -> dict | None:
        """Analytic reference values at ``force`` [N] (None: no closed form)."""
        return None

    def reference_errors(self, out: dict, ref: dict) -> dict:
        """Relative errors of the summary ``out`` against ``ref``."""
        return {}

    def summarize_size(self, out: dict, cc, sol, p: np.ndarray, s: float) -> None:
        """Add the kind's contact-size estimators to the summary ``out`` (in place)."""

    def zone_edge(self, grid) -> np.ndarray | None:
        """Mask of zone-edge nodes (contact there: the zone is too small), or None."""
        return None

    def tangential_reference(self, spec, N: float, mu: float) -> dict:
        """Closed-form tangential values for the summary ({} if none)."""
        return {}

    def tangential_reference_curve(self, spec, N: float, mu: float):
        """(u, T) of the closed-form virgin curve, or None."""
        return None

    # -- plot labels ---------------------------------------------------------------
    reference_label = "Hertz"
    profile_rows = (("y0", "FE, y = 0"),)

    def draw_reference_contact(self, ax, ref: dict) -> None:
        """Outline of the reference contact on an x-y plot in mm."""

    def reference_size(self, ref: dict) -> float:
        """Reference contact size (radius / half-width) [m]."""
        return float("nan")

    def reference_f_approach(self, ref: dict, forces: np.ndarray):
        """Reference approach [m] at ``forces`` [N] from ``ref`` (None: no closed form)."""
        return None


class Sphere(Body):
    """A sphere of radius R on a plane (quarter model)."""

    name = "sphere"
    required = ("radius",)
    size_key = "contact_radius"
    #: Hertz sizes a tiny load's zone well (1e-6 N, R 10 mm: a within 0.3 % at
    #: 9 nodes per side). Not the cylinder: at tiny loads its contact is set by
    #: the end effect, and a 2D-Hertz-sized zone puts contact on its edge.
    zone_from_load = True

    def validate(self, spec):
        super().validate(spec)
        zx, _ = self.zone(spec)
        if zx >= MAX_CONTACT_SHARE * spec.zone_margin * spec.radius * 1.0000001:
            # a = pi R p0 / (2 E*) at a = MAX_CONTACT_SHARE R
            p_max = 2.0 * spec.Estar * MAX_CONTACT_SHARE / math.pi
            p_max = _floor3(p_max)  # printed, then typed back: never rounded up past the limit
            raise ValueError(f"the potential contact zone (half-width {zx:.3g} m, sized for the design "
                             f"pressure {spec.p_design:.3g} Pa) is too large for a sphere of radius "
                             f"{spec.radius:.3g} m: give a --p-design of at most {p_max:.3g} Pa (the Hertz peak "
                             f"pressure of a contact radius of {MAX_CONTACT_SHARE:g} R for these materials)")

    def check_load(self, spec, force):
        """Refuse a force whose Hertz contact radius is outside [MIN_CONTACT_SHARE,
        MAX_CONTACT_SHARE] R."""
        a_min = MIN_CONTACT_SHARE * spec.radius
        f_min = 4.0 * spec.Estar * a_min**3 / (3.0 * spec.radius)
        if force < f_min:
            a = a_min * (max(force, 0.0) / f_min) ** (1.0 / 3.0)
            raise ValueError(f"a force of {force:.4g} N gives a Hertz contact radius of "
                             f"{a:.3g} m, {a / spec.radius:.2g} of the sphere radius {spec.radius:.3g} m: "
                             f"below what the mesh resolves in double precision (a >= "
                             f"{MIN_CONTACT_SHARE:g} R); use a force of at least {f_min:.4g} N")
        a_max = MAX_CONTACT_SHARE * spec.radius
        f_max = 4.0 * spec.Estar * a_max**3 / (3.0 * spec.radius)   # Hertz: a^3 = 3 F R / (4 E*)
        if force > f_max * (1.0 + 3e-9):
            # a from the ratio to f_max: finite for any finite force (a^3 = 3FR/4E* overflows)
            a = a_max * (force / f_max) ** (1.0 / 3.0)
            raise ValueError(f"a force of {force:.4g} N gives a Hertz contact radius of {a:.3g} m, "
                             f"{100 * a / spec.radius:.3g} % of the sphere radius {spec.radius:.3g} m: "
                             f"beyond what the contact model represents (a <= {MAX_CONTACT_SHARE:g} R); "
                             f"use a force of at most {f_max:.4g} N for this sphere, or a larger radius")

    def zone(self, spec):
        Es, R = spec.Estar, spec.radius
        a = hertz.sphere_radius_for_peak(spec.p_design, R, Es)
        if spec.load_hint > 0:
            a = max(a, hertz.sphere(spec.load_hint, R, Es)["a"])
        return spec.zone_margin * a, spec.zone_margin * a

    def meshes(self, spec):
        q, R = spec.grading, spec.radius
        zx, _ = spec.zone()
        near = mesh.NEAR_DEPTH * zx
        xz = mesh.zone_points(zx, spec.n_side, True)
        s = xz[1] - xz[0]
        size = R if spec.model == "real" else max(R, 60.0 * zx)
        xs = np.concatenate([xz, mesh.graded(zx, size, s, q)])
        b2 = mesh.plane_block(xs, xs, size, s, q, xz.size, xz.size, near)
        b1 = (mesh.half_sphere(R, xz, q) if spec.model == "real"
              else mesh.upper_block(xs, xs, size, s, q, xz.size, xz.size, near))
        return b1, b2, s

    def halfspace_gap(self, spec, x, y):
        return (x**2 + y**2) / (2.0 * spec.radius)           # h = r^2 / (2R)

    def bem(self, spec, directions):
        from . import halfspace_bem

        zx, _ = spec.zone()
        return halfspace_bem.sphere(spec.radius, zx, spec.n_side,
                                    ((spec.E1, spec.nu1), (spec.E2, spec.nu2)), directions)

    def reference(self, spec, force):
        return hertz.sphere(force, spec.radius, spec.Estar)

    def reference_errors(self, out, ref):
        return {"error_size": out["contact_radius"] / ref["a"] - 1.0,
                "error_p0": out["p_max"] / ref["p0"] - 1.0,
                "error_approach": out["approach"] / ref["approach"] - 1.0,
                "error_k_n": out["k_n"] / ref["k_n"] - 1.0}

    def summarize_size(self, out, cc, sol, p, s):
        g, P = cc.grid, sol.active
        r = np.hypot(g.x, g.y)
        out["contact_radius_area"] = float(np.sqrt(out["contact_area"] / np.pi))
        fit = fit_edge(r[P], p[P])
        out["contact_radius"] = fit if np.isfinite(fit) else out["contact_radius_area"]
        out["contact_size_method"] = "pressure fit" if np.isfinite(fit) else "area"
        out["under_resolved"] = bool(out["contact_radius"] < MIN_NODES_ACROSS * s)
        share_far(out, cc, sol, out["contact_radius"])

    def zone_edge(self, grid):
        return np.isclose(grid.x, grid.x.max()) | np.isclose(grid.y, grid.y.max())

    def tangential_reference(self, spec, N, mu):
        a = (3 * N * spec.radius / (4 * spec.Estar)) ** (1 / 3)
        Gs = shear_modulus_star(spec.E1, spec.nu1, spec.E2, spec.nu2)
        return {"mindlin": {"contact_radius": a, "k_t": 8 * Gs * a,
                            "u_slip": 3 * mu * N / (16 * Gs * a)}}

    def tangential_reference_curve(self, spec, N, mu):
        from .tangential_reference import mindlin_force

        m = self.tangential_reference(spec, N, mu)["mindlin"]
        u = np.linspace(0, m["u_slip"], 100)
        return u, mindlin_force(u, N, mu, m["contact_radius"], m["k_t"] / (8 * m["contact_radius"]))

    def draw_reference_contact(self, ax, ref):
        t = np.linspace(0, 2 * np.pi, 200)
        ax.plot(ref["a"] * 1e3 * np.cos(t), ref["a"] * 1e3 * np.sin(t), "k-", label="Hertz")

    def reference_size(self, ref):
        return ref["a"]

    def reference_f_approach(self, ref, forces):
        R = ref["a"] ** 2 / ref["approach"]
        a = (3 * forces * R / (4 * ref["k_n"] / (2 * ref["a"]))) ** (1 / 3)
        return a**2 / R


class Cylinder(Body):
    """A cylinder of radius R and length L (axis along y) on a plane (quarter model)."""

    name = "cylinder"
    required = ("radius", "length")
    size_key = "contact_halfwidth"
    peak_key = "p_mid_max"
    reference_label = "2D Hertz"
    profile_rows = (("y0", "FE, y = 0"), ("ymax", "FE, end y = L/2"))

    def check_load(self, spec, force):
        b = hertz.cylinder(force, spec.length, spec.radius, spec.Estar)["b"]
        if b > MAX_CONTACT_SHARE * spec.radius * (1.0 + 1e-9):
            b_max = MAX_CONTACT_SHARE * spec.radius
            f_max = spec.length * math.pi * spec.Estar * b_max**2 / (4.0 * spec.radius)
            raise ValueError(f"a force of {force:.4g} N gives a 2D Hertz contact half-width of {b:.3g} m, "
                             f"{100 * b / spec.radius:.0f} % of the cylinder radius {spec.radius:.3g} m: "
                             f"beyond what the contact model represents (b <= {MAX_CONTACT_SHARE:g} R); "
                             f"use a force of at most {f_max:.4g} N for this cylinder, or a larger diameter or length")

    def zone(self, spec):
        Es, R = spec.Estar, spec.radius
        b = hertz.cylinder_halfwidth_for_peak(spec.p_design, R, Es)
        if spec.load_hint > 0:
            b = max(b, hertz.cylinder(spec.load_hint, spec.length, R, Es)["b"])
        # the edge effect widens the contact at the ends (thesis Fig. 5)
        return min(CYLINDER_END_WIDENING * spec.zone_margin * b, 0.5 * R), 0.5 * spec.length

    def meshes(self, spec):
        q, R = spec.grading, spec.radius
        zx, zy = spec.zone()
        n = spec.n_side
        near = mesh.NEAR_DEPTH * zx
        xz = mesh.zone_points(zx, n, True)
        s = xz[1] - xz[0]
        yz = mesh.cylinder_lines(zy, s, n)
        size = R
        xs = np.concatenate([xz, mesh.graded(zx, size, s, q)])
        ys = np.concatenate([yz, mesh.graded(zy, zy + size, yz[-1] - yz[-2], q)])
        b2 = mesh.plane_block(xs, ys, size, s, q, xz.size, yz.size, near)
        b1 = (mesh.half_cylinder(R, xz, yz, q) if spec.model == "real"
              else mesh.upper_block(xs, yz, size, s, q, xz.size, yz.size, near))
        return b1, b2, s

    def halfspace_gap(self, spec, x, y):
        return x**2 / (2.0 * spec.radius)

    def bem(self, spec, directions):
        from . import halfspace_bem

        zx, _ = spec.zone()
        n = spec.n_side
        return halfspace_bem.cylinder(spec.radius, spec.length, zx, n, n,
                                      ((spec.E1, spec.nu1), (spec.E2, spec.nu2)), directions)

    def reference(self, spec, force):
        return hertz.cylinder(force, spec.length, spec.radius, spec.Estar)

    def reference_errors(self, out, ref):
        return {"error_size": out["contact_halfwidth"] / ref["b"] - 1.0,
                "error_p0": out["p_mid_max"] / ref["p0"] - 1.0}

    def summarize_size(self, out, cc, sol, p, s):
        g, P = cc.grid, sol.active
        mid = np.abs(g.y) <= 1e-9 * s
        end = np.abs(g.y - g.y.max()) <= 1e-9 * s
        out["contact_halfwidth_mid_extent"] = row_extent(g.x[mid], P[mid], s)
        fit = fit_edge(g.x[mid & P], p[mid & P])
        out["contact_halfwidth"] = fit if np.isfinite(fit) else out["contact_halfwidth_mid_extent"]
        out["contact_size_method"] = "pressure fit" if np.isfinite(fit) else "extent"
        out["under_resolved"] = bool(out["contact_halfwidth"] < MIN_NODES_ACROSS * s)
        out["contact_halfwidth_end"] = row_extent(g.x[end], P[end], s)
        share_far(out, cc, sol, out["contact_halfwidth"])
        out["p_mid_max"] = float(p[mid].max())
        out["p_end_max"] = float(p[end].max())

    def zone_edge(self, grid):
        return np.isclose(grid.x, grid.x.max())

    def draw_reference_contact(self, ax, ref):
        for s in (-1, 1):
            ax.axvline(s * ref["b"] * 1e3, color="k", label="Hertz" if s > 0 else None)

    def reference_size(self, ref):
        return ref["b"]


class FlatFace(Body):
    """The damper's flat face W x L (width along x, length along y) on a plane (half model).

    Body 1 is a block of height ``spec.height`` (0: max(W, L/2)) above the face;
    the normal resultant may be eccentric along x (a second rigid DOF, the
    rotation about y).
    """

    name = "flat"
    required = ("length", "width")
    symmetry = "half"
    curved = False

    def check_load(self, spec, force):
        """Refuse a force whose mean pressure lies outside [MIN_CONTACT_STRAIN,
        MAX_CONTACT_STRAIN] E* (double precision; linear elasticity's small strains)."""
        area = spec.width * spec.length
        f_min, f_max = (s * spec.Estar * area for s in (MIN_CONTACT_STRAIN, MAX_CONTACT_STRAIN))
        if force < f_min:
            raise ValueError(f"a force of {force:.4g} N gives a mean pressure below {MIN_CONTACT_STRAIN:g} E* on "
                             f"the {spec.width:.3g} x {spec.length:.3g} m face, where the contact forces leave "
                             f"double precision; give at least {f_min:.4g} N")
        if force > f_max:
            raise ValueError(f"a force of {force:.4g} N gives a mean pressure above {MAX_CONTACT_STRAIN:g} E* on "
                             f"the {spec.width:.3g} x {spec.length:.3g} m face: beyond the small strains of the "
                             f"linear-elastic model; give at most {f_max:.4g} N")

    def check_approach(self, spec, approach):
        """Refuse an approach outside [MIN_CONTACT_STRAIN, MAX_CONTACT_STRAIN] of the face's
        smaller side."""
        side = min(spec.width, spec.length)
        if approach < MIN_CONTACT_STRAIN * side:
            raise ValueError(f"an approach of {approach:g} m is below {MIN_CONTACT_STRAIN:g} of the face's smaller "
                             f"side ({side:.3g} m), where the contact forces leave double precision; give at "
                             f"least {MIN_CONTACT_STRAIN * side:.3g} m")
        if approach > MAX_CONTACT_STRAIN * side:
            raise ValueError(f"an approach of {approach:g} m is above {MAX_CONTACT_STRAIN:g} of the face's smaller "
                             f"side ({side:.3g} m): beyond the small strains of the linear-elastic model; give "
                             f"at most {MAX_CONTACT_STRAIN * side:.3g} m")

    def check_eccentricity(self, spec, eccentricity):
        if eccentricity is not None and abs(eccentricity) >= spec.width / 2:
            raise ValueError(f"eccentricity {eccentricity:g} m lies outside the face "
                             f"(|e| < W/2 = {spec.width / 2:g} m)")

    def key_model(self, spec):
        return "halfspace"  # a flat face has no curvature to model

    def zone(self, spec):
        return 0.5 * spec.width, 0.5 * spec.length

    def body_height(self, spec) -> float:
        """Height of body 1 above the face [m]: ``spec.height`` or max(W, L/2)."""
        zx, zy = self.zone(spec)
        return spec.height or max(2.0 * zx, zy)

    def meshes(self, spec):
        q = spec.grading
        zx, zy = spec.zone()
        near = mesh.NEAR_DEPTH * zx
        xz = mesh.zone_points(zx, spec.n_side, False)
        s = xz[1] - xz[0]
        ny = max(3, int(round(zy / s)) + 1)
        yz = np.linspace(0.0, zy, ny)
        size = max(2.0 * zx, zy)
        xr = mesh.graded(zx, zx + size, s, q)
        xs = np.concatenate([-xr[::-1], xz, xr])
        ys = np.concatenate([yz, mesh.graded(zy, zy + size, yz[1] - yz[0], q)])
        b2 = mesh.plane_block(xs, ys, size, s, q, xz.size, yz.size, near)
        b1 = mesh.upper_block(xz, yz, self.body_height(spec), s, q, xz.size, yz.size, near)
        return b1, b2, s

    def rigid(self, x):
        return np.stack([np.ones_like(x), x], axis=1)   # approach, rotation about y


for _kind in (Sphere(), Cylinder(), FlatFace()):
    register(_kind)

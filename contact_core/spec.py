"""Specification of a contact pair: geometry, materials, model variant, grid.

Body 1 is the curved body (sphere, cylinder) or the damper's flat face, body 2
the plane. Axes: z normal to the contact plane (body 1 above), a cylinder's axis
and a flat face's length L along y, the face width W along x.

The potential contact zone is sized as in the thesis (Appendix A.1.2): the Hertz
contact for a design peak pressure (``p_design``, 2000 MPa), enlarged by
``zone_margin``, or the Hertz contact of ``load_hint`` if that is larger.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from . import bodies, hertz

#: Steel, the default for both bodies.
STEEL_E = 200e9
STEEL_NU = 0.3
#: Largest contact grid accepted: 81 nodes per side is ~0.25 M DOF per body
#: for the sphere (see also mesh.MAX_CONTACT_NODES).
MAX_GRID = 81
MODELS = ("real", "halfspace")
#: Largest Young's modulus [Pa]: ten times diamond's (1.2e12 Pa); far beyond, the Hertz
#: relations (E* a^3) leave double precision.
MAX_MODULUS = 1e13
#: Smallest Young's modulus [Pa]: a soft elastomer's (1e5 Pa); far below, the Hertz
#: contact radius of any load overflows (E = 1e-300 Pa: "a contact radius of inf m").
MIN_MODULUS = 1e5


@dataclass(frozen=True)
class ContactSpec:
    """A contact pair (SI units).

    Parameters
    ----------
    body : str
        Name of a registered body kind (``contact_core.bodies``: "sphere",
        "cylinder", "flat"); ``spec.kind`` is its class instance.
    radius : float
        Sphere or cylinder radius R [m] (cylinder: D/2).
    length : float
        Cylinder length or flat-face length L along y [m].
    width : float
        Flat-face width W along x [m].
    E1, nu1, E2, nu2 : float
        Young's modulus [Pa] and Poisson ratio of body 1 (curved/face) and 2 (plane).
    model : {"real", "halfspace"}
        "real": a true half-sphere / half-cylinder on a block; "halfspace": block
        on block with the curvature only in the gap h = r^2 / (2R).
    grid : int
        Contact-zone nodes per side of the full model (an even value is raised
        by one so that a node sits on each symmetry plane).
    p_design : float
        Design peak pressure sizing the potential contact zone [Pa].
    load_hint : float
        A normal force [N] the zone must hold (0: none).
    zone_margin : float
        Potential zone / Hertz contact size at ``p_design``.
    grading : float
        Growth ratio of element sizes away from the contact zone.
    height : float
        Flat face: height of body 1 above the face [m] (0: max(W, L/2)).
    """

    body: str = "sphere"
    radius: float = 0.01
    length: float = 0.0
    width: float = 0.0
    E1: float = STEEL_E
    nu1: float = STEEL_NU
    E2: float = STEEL_E
    nu2: float = STEEL_NU
    model: str = "real"
    grid: int = 21
    p_design: float = 2000e6
    load_hint: float = 0.0
    zone_margin: float = 1.15
    grading: float = 1.45
    height: float = 0.0

    def __post_init__(self):
        validate(self)

    @property
    def Estar(self) -> float:
        """Contact modulus E* [Pa]."""
        return hertz.contact_modulus(self.E1, self.nu1, self.E2, self.nu2)

    @property
    def n_side(self) -> int:
        """Contact-zone nodes per side actually used (odd)."""
        return self.grid + 1 - self.grid % 2

    @property
    def kind(self) -> bodies.Body:
        """The body kind (``contact_core.bodies``) named by ``body``."""
        return bodies.get(self.body)

    def zone(self) -> tuple[float, float]:
        """Half-extents (zx, zy) [m] of the potential contact zone of the full model."""
        return self.kind.zone(self)

    def key_dict(self) -> dict:
        """Fields that define the FE model (for the cache key).

        The zone sizing inputs (p_design, load_hint, zone_margin) enter through
        the zone they produce, so load cases below the design pressure share
        one condensed model.
        """
        d = asdict(self)
        for name in ("p_design", "load_hint", "zone_margin"):
            d.pop(name)
        if not self.height:
            d.pop("height")  # the default body height: keys of older specs stay valid
        d["zone"] = [float(v) for v in self.zone()]
        d["model"] = self.kind.key_model(self)
        return d


def _positive(name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")


def validate(spec: ContactSpec) -> None:
    """Raise ValueError with a clear message for an inconsistent specification."""
    kind = bodies.get(spec.body)
    if spec.model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, got {spec.model!r}")
    for name in ("E1", "E2"):
        _positive(name, getattr(spec, name))
        if getattr(spec, name) > MAX_MODULUS:
            raise ValueError(f"{name} = {getattr(spec, name):.4g} Pa is above the limit {MAX_MODULUS:g} Pa "
                             "(ten times diamond's Young's modulus)")
        if getattr(spec, name) < MIN_MODULUS:
            raise ValueError(f"{name} = {getattr(spec, name):.4g} Pa is below the limit {MIN_MODULUS:g} Pa "
                             "(a soft elastomer's Young's modulus)")
    for name in ("nu1", "nu2"):
        nu = getattr(spec, name)
        if not (-1.0 < nu < 0.5):
            raise ValueError(f"{name} must lie in (-1, 0.5) (0.5 is incompressible), got {nu!r}")
    kind.validate(spec)
    if not isinstance(spec.grid, int) or spec.grid < 3:
        raise ValueError(f"grid must be an integer >= 3, got {spec.grid!r}")
    if spec.grid > MAX_GRID:
        raise ValueError(f"grid {spec.grid} is beyond what one machine condenses in minutes "
                         f"(max {MAX_GRID}; 41 already gives a and p0 within 0.2 % of Hertz)")
    _positive("p_design", spec.p_design)
    if spec.load_hint < 0:
        raise ValueError(f"load_hint must be >= 0, got {spec.load_hint!r}")
    if not spec.zone_margin >= 1.0:
        raise ValueError("zone_margin must be >= 1")
    if not 1.0 < spec.grading <= 3.0:
        raise ValueError("grading must lie in (1, 3]")

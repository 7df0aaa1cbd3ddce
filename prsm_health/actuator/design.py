"""PRSM designs: geometry, materials and mass properties, with per-paper presets.

Everything is SI (m, kg, kg·m², Pa, rad). A design is validated once, at construction; an
invalid value raises :class:`~prsm_health.core.errors.ParameterError` naming the field, the value
and the allowed range.

Conventions
-----------
``contact_angle`` (β) is the angle between the thread contact normal and the radial plane
(ball-bearing convention, paper 05's β, paper 04's β). The axial component of a normal force
N is ``N·sin β·cos λ`` and the radial component ``N·cos β``. Paper 01 gives the *thread profile
angle* (90°), whose half (45°) is measured from the axis; its contact angle is 90° − 45° = 45°.

References
----------
- Paper 01 (docs/references.md): parameter table §3.
- Paper 02 (docs/references.md): parameter table.
- Paper 03 (docs/references.md): eqs. (1)–(5), (14).
- Paper 04 (docs/references.md): base parameters.
- Paper 05 (docs/references.md): parameter table.
"""

from __future__ import annotations

import math
from dataclasses import MISSING, dataclass, field, fields, replace

from prsm_health.core.errors import (
    ParameterError,
    require,
    require_known_keys,
    require_positive,
    require_range,
)

from .recirculation_spec import RecirculationSpec

#: Relative tolerance of the concentric condition d_n = d_s + 2·d_r (paper 03 eq. 1). Real
#: designs shift the roller pitch diameter by a few tenths of a percent to tune the contact
#: point, so exact equality is not demanded; 0.5 % of d_n admits that and refuses typos.
CONCENTRIC_TOLERANCE = 5e-3

#: Relative tolerance of the roller–nut helix match n_n·d_r = n_r·d_n and of the gear ratio
#: z_ring/z_roller = d_n/d_r. A mismatch beyond 1 % makes the roller drift axially in the nut
#: (paper 03 §1, Jones et al.), which no standard PRSM tolerates.
LEAD_TOLERANCE = 1e-2

#: Largest plausible value [m] of a design's lengths (PRSM screws run from a few mm to a few
#: hundred mm, pitches and gear modules from 0.5 to a few mm): a larger value is a length typed
#: in millimetres, refused naming its own key before any check that combines lengths would
#: blame another (``pitch = 2`` would otherwise fail as a negative screw root diameter).
LENGTH_LIMITS = {"pitch": 0.1, "lead": 0.1, "module": 0.1, "screw_free_length": 10.0}
#: For every other length of a design.
DEFAULT_LENGTH_LIMIT = 1.0
#: The lengths [m] of :class:`PRSMDesign` itself (the gear's are checked by the gear).
LENGTHS = (
    "screw_diameter",
    "roller_diameter",
    "nut_diameter",
    "pitch",
    "nut_outer_diameter",
    "screw_free_length",
    "screw_bore_diameter",
    "thread_addendum",
    "roller_profile_radius",
    "nut_length",
)


def require_metres(field: str, value) -> None:
    """Refuse a length that reads as millimetres: above its :data:`LENGTH_LIMITS`."""
    limit = LENGTH_LIMITS.get(field.rsplit(".", 1)[-1], DEFAULT_LENGTH_LIMIT)
    if isinstance(value, (int, float)) and value > limit:
        raise ParameterError(
            field,
            value,
            f"must be ≤ {limit:g} m: lengths are in metres — typed in millimetres? "
            f"{value:g} mm = {value * 1e-3:g} m",
        )


@dataclass(frozen=True)
class Material:
    """Isotropic elastic material.

    Parameters
    ----------
    youngs_modulus : float [Pa]
    poisson_ratio : float [-]
    density : float [kg/m³]
    shear_modulus : float or None [Pa]
        ``None`` derives it as E / (2(1 + ν)); paper 05 prints its own value.
    """

    youngs_modulus: float = 2.10e11
    poisson_ratio: float = 0.30
    density: float = 7850.0
    shear_modulus: float | None = None

    def __post_init__(self):
        require_positive("material.youngs_modulus", self.youngs_modulus)
        require_range("material.poisson_ratio", self.poisson_ratio, 0.0, 0.5, inclusive=False)
        require_positive("material.density", self.density)
        if self.shear_modulus is not None:
            require_positive("material.shear_modulus", self.shear_modulus)

    @property
    def G(self) -> float:
        """Shear modulus [Pa]."""
        if self.shear_modulus is not None:
            return self.shear_modulus
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def plane_strain_modulus(self) -> float:
        """E / (1 − ν²) [Pa]."""
        return self.youngs_modulus / (1.0 - self.poisson_ratio**2)


#: Bearing steel (GCr15 / 52100), the material every paper uses; E and ν of paper 04.
STEEL = Material()


@dataclass(frozen=True)
class GearGeometry:
    """Roller-end spur gear meshing with the nut's internal ring gear.

    Parameters
    ----------
    ring_teeth : int
        Teeth of the internal ring gear, z_ring (paper 01: z2 = 65).
    roller_teeth : int
        Teeth of the roller-end gear, z_roller.
    module : float [m]
    pressure_angle : float [rad]
        Standard pressure angle α0 (paper 01: 20°, from Ψ_Ng = 11π/18 = π/2 + α0).
    face_width : float [m]
        Full face width L of the roller gear.
    addendum_coefficient, dedendum_coefficient : float [-]
        Tooth proportions in modules (1.0 and 1.25 for a standard full-depth tooth).
    """

    ring_teeth: int
    roller_teeth: int
    module: float
    pressure_angle: float = math.radians(20.0)
    face_width: float = 3e-3
    addendum_coefficient: float = 1.0
    dedendum_coefficient: float = 1.25

    def __post_init__(self):
        require(
            isinstance(self.ring_teeth, int) and self.ring_teeth >= 12,
            "gear.ring_teeth",
            self.ring_teeth,
            "must be an integer ≥ 12",
        )
        require(
            isinstance(self.roller_teeth, int) and 6 <= self.roller_teeth < self.ring_teeth,
            "gear.roller_teeth",
            self.roller_teeth,
            f"must be an integer in [6, ring_teeth = {self.ring_teeth})",
        )
        require_positive("gear.module", self.module)
        for name in ("module", "face_width"):
            require_metres(f"gear.{name}", getattr(self, name))
        require_range(
            "gear.pressure_angle",
            self.pressure_angle,
            math.radians(10),
            math.radians(35),
            unit="rad (10°–35°)",
        )
        require_positive("gear.face_width", self.face_width)
        require_range("gear.addendum_coefficient", self.addendum_coefficient, 0.5, 1.5)
        require_range("gear.dedendum_coefficient", self.dedendum_coefficient, 0.8, 1.6)

    @property
    def ring_pitch_diameter(self) -> float:
        """z_ring·m [m]."""
        return self.ring_teeth * self.module

    @property
    def roller_pitch_diameter(self) -> float:
        """z_roller·m [m]."""
        return self.roller_teeth * self.module


@dataclass(frozen=True)
class MassProperties:
    """Lumped masses [kg] and polar moments of inertia about each body's own axis [kg·m²]."""

    screw_mass: float
    screw_inertia: float
    nut_mass: float
    nut_inertia: float
    roller_mass: float
    roller_inertia: float
    carrier_mass: float
    carrier_inertia: float

    def __post_init__(self):
        for f in fields(self):
            require_positive(f"masses.{f.name}", getattr(self, f.name))


@dataclass(frozen=True)
class PRSMDesign:
    """Geometry, materials and masses of a planetary roller screw mechanism.

    Parameters
    ----------
    name : str
        Preset or user name.
    variant : {"standard", "recirculating"}
        Standard PRSM (threaded rollers, ring gears) or recirculating PRSM (grooved rollers,
        cam-ring reset, no gears; paper 03).
    screw_diameter, roller_diameter, nut_diameter : float [m]
        Thread pitch diameters d_s, d_r, d_n. Must satisfy d_n = d_s + 2·d_r within
        :data:`CONCENTRIC_TOLERANCE` (paper 03 eq. 1).
    pitch : float [m]
        Axial distance between adjacent thread crests, common to screw, rollers and nut.
    screw_starts, nut_starts, roller_starts : int
        Number of thread starts. Lead = starts·pitch. Standard PRSM: n_s = n_n and
        n_n·d_r = n_r·d_n; recirculating: n_s = n_n (eq. 2) and grooved rollers (n_r = 0).
    n_rollers : int
    contact_angle : float [rad]
        Angle between the thread contact normal and the radial plane (see module docstring).
    engaged_threads : int
        Thread turns of one roller engaged with the screw (and, equally, with the nut).
    thread_addendum : float or None [m]
        Radial height of the thread crest above the pitch diameter. ``None``: 0.25·p·tan β,
        a quarter of the sharp-V depth, the truncation of common PRSM profiles.
    roller_profile_radius : float or None [m]
        Radius of the roller's circular thread profile. ``None``: r_r / cos β, the radius whose
        normal at the pitch point makes the contact angle β (paper 03 eq. 5, paper 05 ρ_11).
    nut_outer_diameter : float [m]
    screw_bore_diameter : float [m]
        0 for a solid screw.
    screw_free_length : float [m]
        Screw length between its axial bearing and the nut, loaded in tension/compression.
    nut_length : float or None [m]
        Threaded nut length; ``None``: engaged_threads·pitch.
    screw_material, roller_material, nut_material : Material
    gear : GearGeometry or None
        Required for the standard variant, absent for the recirculating one.
    recirculation : RecirculationSpec or None
        Recirculating variant only: the carrier, cam-ring and assembly dimensions it sets
        (:mod:`prsm_health.actuator.recirculation_spec`); the rest follow paper 03's rules.
    masses : MassProperties
    reference : str
        Where the numbers come from.
    """

    name: str
    variant: str
    screw_diameter: float
    roller_diameter: float
    nut_diameter: float
    pitch: float
    screw_starts: int
    nut_starts: int
    roller_starts: int
    n_rollers: int
    contact_angle: float
    engaged_threads: int
    masses: MassProperties
    nut_outer_diameter: float
    screw_free_length: float = 0.1
    screw_bore_diameter: float = 0.0
    thread_addendum: float | None = None
    roller_profile_radius: float | None = None
    nut_length: float | None = None
    screw_material: Material = STEEL
    roller_material: Material = STEEL
    nut_material: Material = STEEL
    gear: GearGeometry | None = None
    recirculation: RecirculationSpec | None = None
    reference: str = field(default="user", compare=False)

    def __post_init__(self):
        self._validate()

    # ---------------------------------------------------------------- validation
    def _validate(self) -> None:
        require(
            self.variant in ("standard", "recirculating"),
            "design.variant",
            self.variant,
            "must be 'standard' or 'recirculating'",
        )
        for name in (
            "screw_diameter",
            "roller_diameter",
            "nut_diameter",
            "pitch",
            "nut_outer_diameter",
            "screw_free_length",
        ):
            require_positive(f"design.{name}", getattr(self, name))
        for name in LENGTHS:
            require_metres(f"design.{name}", getattr(self, name))
        require_range(
            "design.contact_angle",
            self.contact_angle,
            math.radians(15.0),
            math.radians(75.0),
            unit="rad (15°–75°)",
        )
        for name in ("thread_addendum", "roller_profile_radius", "nut_length"):
            value = getattr(self, name)
            if value is not None:
                require_positive(f"design.{name}", value)
        require(
            isinstance(self.screw_bore_diameter, (int, float))
            and 0.0 <= self.screw_bore_diameter < self.screw_root_diameter,
            "design.screw_bore_diameter",
            self.screw_bore_diameter,
            f"must lie in [0, screw root diameter = {self.screw_root_diameter:.6g} m)",
        )
        for name, low in (("n_rollers", 2), ("engaged_threads", 1), ("screw_starts", 1)):
            value = getattr(self, name)
            require(
                isinstance(value, int) and value >= low,
                f"design.{name}",
                value,
                f"must be an integer ≥ {low}",
            )
        self._validate_concentric()
        self._validate_leads()
        self._validate_roller_count()
        require(
            self.nut_outer_diameter > self.nut_root_diameter,
            "design.nut_outer_diameter",
            self.nut_outer_diameter,
            f"must exceed the nut root diameter {self.nut_root_diameter:.6g} m",
        )
        if self.roller_profile_radius is not None:
            require(
                self.roller_profile_radius > self.roller_diameter / 2,
                "design.roller_profile_radius",
                self.roller_profile_radius,
                f"must exceed the roller pitch radius {self.roller_diameter / 2:.6g} m",
            )

    def _validate_concentric(self) -> None:
        expected = self.screw_diameter + 2.0 * self.roller_diameter
        require(
            abs(self.nut_diameter - expected) <= CONCENTRIC_TOLERANCE * expected,
            "design.nut_diameter",
            self.nut_diameter,
            f"must equal d_s + 2·d_r = {expected:.6g} m within "
            f"{CONCENTRIC_TOLERANCE:.1%} (concentric condition, paper 03 eq. 1)",
        )

    def _validate_leads(self) -> None:
        require(
            self.nut_starts == self.screw_starts,
            "design.nut_starts",
            self.nut_starts,
            f"must equal screw_starts = {self.screw_starts} so screw and nut leads match "
            "(paper 03 eqs. 2–3)",
        )
        if self.variant == "recirculating":
            require(
                self.roller_starts == 0,
                "design.roller_starts",
                self.roller_starts,
                "must be 0: recirculating rollers are grooved, without helix (paper 03 §2)",
            )
            require(
                self.gear is None,
                "design.gear",
                "GearGeometry",
                "must be None: a recirculating PRSM has no ring gear",
            )
            return
        require(
            self.recirculation is None,
            "design.recirculation",
            "RecirculationSpec",
            "must be absent for a standard PRSM: only the recirculating variant has a cam ring",
        )
        require(
            isinstance(self.roller_starts, int) and self.roller_starts >= 1,
            "design.roller_starts",
            self.roller_starts,
            "must be an integer ≥ 1 for a standard PRSM",
        )
        # Roller and nut must share the helix angle, else the roller walks out of the nut.
        ideal_nut_starts = self.roller_starts * self.nut_diameter / self.roller_diameter
        require(
            abs(self.nut_starts - ideal_nut_starts) <= LEAD_TOLERANCE * ideal_nut_starts,
            "design.nut_starts",
            self.nut_starts,
            f"must equal roller_starts·d_n/d_r = {ideal_nut_starts:.4g} within "
            f"{LEAD_TOLERANCE:.0%} (roller and nut helix angles must match)",
        )
        require(
            self.gear is not None,
            "design.gear",
            None,
            "a standard PRSM needs its roller/ring gear (GearGeometry)",
        )
        ratio = self.gear.ring_teeth / self.gear.roller_teeth
        thread_ratio = self.nut_diameter / self.roller_diameter
        require(
            abs(ratio - thread_ratio) <= LEAD_TOLERANCE * thread_ratio,
            "gear.ring_teeth / gear.roller_teeth",
            ratio,
            f"must equal d_n/d_r = {thread_ratio:.4g} within {LEAD_TOLERANCE:.0%} "
            "(gear and thread rolling must agree)",
        )
        self._validate_gear_fits_nut()

    def _validate_gear_fits_nut(self) -> None:
        # The roller gear turns on the roller's axis, on the orbit d_c = d_s + d_r: the internal
        # pair's centre distance m·(z_ring − z_roller)/2 must be the orbit radius, i.e. the ring
        # gear's pitch circle is the nut's (the teeth ratio is checked against d_n/d_r above).
        g = self.gear
        orbit = self.orbit_diameter
        tooth_gap = g.ring_teeth - g.roller_teeth
        low, high = ((1 - s * CONCENTRIC_TOLERANCE) * orbit / tooth_gap for s in (1, -1))
        require(
            low <= g.module <= high,
            "gear.module",
            g.module,
            f"must lie in [{low:.6g}, {high:.6g}] m with gear.ring_teeth = {g.ring_teeth} and "
            f"gear.roller_teeth = {g.roller_teeth}: the ring gear (pitch diameter "
            f"module·ring_teeth = {g.ring_pitch_diameter:.6g} m) must fit the nut (d_n = "
            f"{self.nut_diameter:.6g} m), its centre distance module·(ring_teeth − "
            f"roller_teeth)/2 the roller orbit radius (d_s + d_r)/2 = {orbit / 2:.6g} m within "
            f"{CONCENTRIC_TOLERANCE:.1%}",
        )

    def _validate_roller_count(self) -> None:
        # Neighbouring rollers must not touch: chord between centres > roller major diameter.
        chord = self.orbit_diameter * math.sin(math.pi / self.n_rollers)
        max_geometric = int(
            math.floor(
                math.pi / math.asin(min(1.0, self.roller_major_diameter / self.orbit_diameter))
            )
        )
        require(
            chord > self.roller_major_diameter,
            "design.n_rollers",
            self.n_rollers,
            f"must be ≤ {max_geometric}: rollers of major diameter "
            f"{self.roller_major_diameter:.4g} m overlap on the orbit d_c = "
            f"{self.orbit_diameter:.4g} m",
        )
        if self.variant == "recirculating":
            limit = recirculating_roller_limit(self)
            require(
                self.n_rollers < limit,
                "design.n_rollers",
                self.n_rollers,
                f"must be < π·d_c·tan(α/2)/(2·lead) = {limit:.4g}: at most one roller in the "
                "threadless area (paper 03 eqs. 11–14)",
            )

    # ---------------------------------------------------------------- derived geometry
    @property
    def screw_lead(self) -> float:
        """L_s = n_s·p [m]."""
        return self.screw_starts * self.pitch

    @property
    def nut_lead(self) -> float:
        """L_n = n_n·p [m]."""
        return self.nut_starts * self.pitch

    @property
    def roller_lead(self) -> float:
        """L_r = n_r·p [m] (0 for grooved recirculating rollers)."""
        return self.roller_starts * self.pitch

    @property
    def screw_lead_angle(self) -> float:
        """λ_s = atan(L_s / (π d_s)) [rad]."""
        return math.atan(self.screw_lead / (math.pi * self.screw_diameter))

    @property
    def nut_lead_angle(self) -> float:
        """λ_n = atan(L_n / (π d_n)) [rad]."""
        return math.atan(self.nut_lead / (math.pi * self.nut_diameter))

    @property
    def roller_lead_angle(self) -> float:
        """λ_r = atan(L_r / (π d_r)) [rad]."""
        return math.atan(self.roller_lead / (math.pi * self.roller_diameter))

    @property
    def orbit_diameter(self) -> float:
        """Diameter of the roller-centre orbit d_c = d_s + d_r [m]."""
        return self.screw_diameter + self.roller_diameter

    @property
    def addendum(self) -> float:
        """Thread crest height above the pitch diameter [m]."""
        if self.thread_addendum is not None:
            return self.thread_addendum
        return 0.25 * self.pitch * math.tan(self.contact_angle)

    @property
    def dedendum(self) -> float:
        """Thread root depth below the pitch diameter [m] (1.25 × addendum, for clearance)."""
        return 1.25 * self.addendum

    @property
    def screw_major_diameter(self) -> float:
        """d_s3 [m]."""
        return self.screw_diameter + 2 * self.addendum

    @property
    def screw_root_diameter(self) -> float:
        """[m]"""
        return self.screw_diameter - 2 * self.dedendum

    @property
    def roller_major_diameter(self) -> float:
        """d_r3 [m]."""
        return self.roller_diameter + 2 * self.addendum

    @property
    def roller_root_diameter(self) -> float:
        """d_r1 [m]."""
        return self.roller_diameter - 2 * self.dedendum

    @property
    def nut_minor_diameter(self) -> float:
        """Crest diameter of the nut's internal thread d_n1 [m]."""
        return self.nut_diameter - 2 * self.addendum

    @property
    def nut_root_diameter(self) -> float:
        """[m]"""
        return self.nut_diameter + 2 * self.dedendum

    @property
    def roller_thread_radius(self) -> float:
        """Radius of the roller's circular thread profile [m]."""
        if self.roller_profile_radius is not None:
            return self.roller_profile_radius
        return 0.5 * self.roller_diameter / math.cos(self.contact_angle)

    @property
    def threaded_nut_length(self) -> float:
        """[m]"""
        return self.nut_length if self.nut_length is not None else self.engaged_threads * self.pitch

    @property
    def roller_tooth_angle(self) -> float:
        """Full tooth angle of the roller profile α = π − 2β [rad] (paper 03 eq. 5)."""
        return math.pi - 2.0 * self.contact_angle

    def with_(self, **changes) -> PRSMDesign:
        """A validated copy with some fields changed."""
        return replace(self, **changes)

    # ---------------------------------------------------------------- dict form
    def to_dict(self) -> dict:
        """Every field, SI units, nested dicts for materials, gear and masses (``None`` kept)."""
        return _to_dict(self)

    @classmethod
    def from_dict(cls, data: dict) -> PRSMDesign:
        """Build from the nested dict form of :meth:`to_dict`.

        An unknown key raises :class:`ParameterError` naming the dotted field
        (``design.gear.modul``) and listing the allowed keys; a value of the wrong type names
        the field and the expected type; then the usual validation runs. Integers are accepted
        for float fields; optional fields (``None`` default) may be left out.
        """
        return _from_dict(cls, data, "design")


_NESTED = {
    "Material": Material,
    "GearGeometry": GearGeometry,
    "MassProperties": MassProperties,
    "RecirculationSpec": RecirculationSpec,
}


def _to_dict(obj) -> dict:
    out = {}
    for f in fields(obj):
        value = getattr(obj, f.name)
        out[f.name] = _to_dict(value) if type(value).__name__ in _NESTED else value
    return out


def _expected(annotation: str) -> tuple[str, bool]:
    """(base type name, optional) of a field annotation such as ``"float | None"``."""
    optional = annotation.endswith(" | None")
    return annotation.removesuffix(" | None"), optional


def _from_dict(kind: type, data, where: str):
    if not isinstance(data, dict):
        raise ParameterError(where, data, f"must be a table of {kind.__name__} fields")
    require_known_keys(where, data, [f.name for f in fields(kind)])
    values = {}
    for f in fields(kind):
        name = f"{where}.{f.name}"
        base, optional = _expected(str(f.type))
        if f.name not in data:
            if f.default is MISSING and f.default_factory is MISSING:
                raise ParameterError(name, None, f"missing: a required {base} field")
            continue
        value = data[f.name]
        if value is None and optional:
            values[f.name] = None
        elif base in _NESTED:
            values[f.name] = _from_dict(_NESTED[base], value, name)
        elif base == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(name, value, "wrong type: expected a number (float)")
            values[f.name] = float(value)
        elif base == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                raise ParameterError(name, value, "wrong type: expected an integer (int)")
            values[f.name] = value
        elif base == "str":
            if not isinstance(value, str):
                raise ParameterError(name, value, "wrong type: expected a string (str)")
            values[f.name] = value
        else:  # pragma: no cover - a field type this function does not know
            raise TypeError(f"{name}: unsupported field type {f.type}")
    return kind(**values)


def recirculating_roller_limit(design: PRSMDesign) -> float:
    """Upper bound on the roller count of a recirculating PRSM, π·d_c·tan(α/2)/(2·L).

    Parameters
    ----------
    design : PRSMDesign

    Returns
    -------
    float [-]
        N must be strictly smaller than this.

    References
    ----------
    Paper 03, eqs. (11)–(13): a roller crossing one thread (a reset stroke of one lead L) in
    the threadless area sweeps the orbital angle β = 2L/(d_c·tan(α/2)) rad (eq. 11), which must
    stay below half the roller spacing, β < φ/2 = π/N (eq. 13). The printed eq. (14),
    N < π·d_c·tan(α/2)/p, drops the factor 2 (it states β < φ); see docs/validation.md.
    """
    return (
        math.pi
        * design.orbit_diameter
        * math.tan(design.roller_tooth_angle / 2)
        / (2.0 * design.screw_lead)
    )


def printed_eq14_limit(design: PRSMDesign) -> float:
    """Paper 03's printed eq. (14) bound π·d_c·tan(α/2)/p, twice the bound of eqs. (11)–(13) [-]."""
    return math.pi * design.orbit_diameter * math.tan(design.roller_tooth_angle / 2) / design.pitch


# ------------------------------------------------------------------------- presets
def _solid_cylinder_inertia(mass: float, radius: float) -> float:
    return 0.5 * mass * radius**2


def _paper01() -> PRSMDesign:
    deg = math.radians
    r_s, r_c = 9.75e-3, 3.25e-3
    j_s = 58e-6  # kg·mm² → kg·m²
    return PRSMDesign(
        name="paper01",
        variant="standard",
        screw_diameter=2 * r_s,
        roller_diameter=2 * r_c,
        nut_diameter=2 * 16.25e-3,
        pitch=2e-3,
        screw_starts=5,
        nut_starts=5,
        roller_starts=1,
        n_rollers=7,
        # Profile angle β = 90°: flank normal 45° from the axis → contact angle 45°.
        contact_angle=deg(45.0),
        engaged_threads=10,  # paper silent: engineering default, see docs/validation.md
        nut_outer_diameter=2 * 32.5e-3,  # paper silent: wall = nut pitch radius
        screw_free_length=0.1,  # paper silent
        gear=GearGeometry(
            ring_teeth=65,  # paper §3.2: z2 = 65
            roller_teeth=13,  # 65·d_r/d_n: the only count with the gear and thread ratios equal
            module=0.5e-3,  # d_n / z2 = 32.5 mm / 65
            pressure_angle=deg(20.0),  # Ψ_Ng = 11π/18 = π/2 + α0
            face_width=3e-3,  # paper silent
        ),
        masses=MassProperties(
            # m_s not given: a solid steel screw with J_s = 58 kg·mm² at r_s → m = 2J/r².
            screw_mass=2 * j_s / r_s**2,
            screw_inertia=j_s,
            nut_mass=20.0,
            # J_N not given: a thick ring r_N … 2r_N of mass m_N.
            nut_inertia=0.5 * 20.0 * ((16.25e-3) ** 2 + (32.5e-3) ** 2),
            roller_mass=0.014,
            roller_inertia=0.077e-6,
            carrier_mass=0.016,
            carrier_inertia=2.95e-6,
        ),
        reference="paper 01, §3 parameter table; z2 = 65 from §3.2",
    )


def _paper02() -> PRSMDesign:
    # Printed r_n0 = 15 mm breaks the concentric condition (needs 20 mm): the design preset
    # uses 20 mm; the friction model keeps the printed radii (docs/validation.md).
    r_s, r_r, r_n = 10e-3, 5e-3, 20e-3
    roller_mass = 0.05
    return PRSMDesign(
        name="paper02",
        variant="standard",
        screw_diameter=2 * r_s,
        roller_diameter=2 * r_r,
        nut_diameter=2 * r_n,
        pitch=5e-3 / 4,  # table "pitch 5 mm" read as the screw lead: 4 starts × 1.25 mm
        screw_starts=4,
        nut_starts=4,
        roller_starts=1,
        n_rollers=5,
        contact_angle=math.radians(45.0),  # flank angle β_s = 45°
        engaged_threads=3,  # thread rounds per roller n_t = 3
        nut_outer_diameter=2 * 30e-3,
        gear=GearGeometry(ring_teeth=80, roller_teeth=20, module=0.5e-3, face_width=4e-3),
        masses=MassProperties(
            screw_mass=0.8,
            screw_inertia=_solid_cylinder_inertia(0.8, r_s),
            nut_mass=0.5,
            nut_inertia=0.5 * 0.5 * (r_n**2 + (30e-3) ** 2),
            roller_mass=roller_mass,
            roller_inertia=_solid_cylinder_inertia(roller_mass, r_r),
            carrier_mass=0.1,
            carrier_inertia=0.1 * (r_s + r_r) ** 2,
        ),
        reference="paper 02 parameter table (r_n0 corrected 15 → 20 mm; masses partly defaults)",
    )


def _paper03() -> PRSMDesign:
    # Table 1 is not printed; the geometry is the one that fits most of the paper's numbers
    # (docs/validation.md, design presets): orbit radius 19.75 mm (§3.2), 12 rollers,
    # single-start 1 mm pitch, roller tooth angle α = 90°.
    d_s, d_r = 32e-3, 7.5e-3
    # the roller from its own geometry: a steel cylinder at the pitch diameter (a groove's
    # teeth fill about half of the crest-to-root band) as long as its 10 engaged grooves of
    # 1 mm — 3.5 g (was an assumed 20 g; 3.9 g at the crest diameter)
    roller_length = 10 * 1e-3
    roller_mass = STEEL.density * math.pi / 4 * d_r**2 * roller_length
    return PRSMDesign(
        name="paper03",
        variant="recirculating",
        screw_diameter=d_s,
        roller_diameter=d_r,
        nut_diameter=47e-3,
        pitch=1e-3,
        screw_starts=1,
        nut_starts=1,
        roller_starts=0,
        n_rollers=12,
        contact_angle=math.radians(45.0),  # α = 90° → β = (180° − α)/2
        engaged_threads=10,
        nut_outer_diameter=65e-3,
        gear=None,
        masses=MassProperties(
            screw_mass=1.0,
            screw_inertia=_solid_cylinder_inertia(1.0, d_s / 2),
            nut_mass=0.6,
            nut_inertia=0.5 * 0.6 * ((47e-3 / 2) ** 2 + (65e-3 / 2) ** 2),
            roller_mass=roller_mass,
            roller_inertia=_solid_cylinder_inertia(roller_mass, d_r / 2),
            carrier_mass=0.05,
            carrier_inertia=0.05 * ((d_s + d_r) / 2) ** 2,
        ),
        reference="paper 03 §2–3 (geometry reconstructed, see docs/validation.md)",
    )


def _paper04() -> PRSMDesign:
    d_s, d_r = 21e-3, 7e-3
    # Lead angle 1.74° on d_s = 21 mm → lead π·21·tan 1.74° = 2.00 mm; 5 starts → 0.4 mm pitch.
    lead = math.pi * d_s * math.tan(math.radians(1.74))
    roller_mass = 0.015
    steel = Material(youngs_modulus=210e9, poisson_ratio=0.3)
    return PRSMDesign(
        name="paper04",
        variant="standard",
        screw_diameter=d_s,
        roller_diameter=d_r,
        nut_diameter=35e-3,
        pitch=round(lead / 5, 7),
        screw_starts=5,
        nut_starts=5,
        roller_starts=1,
        n_rollers=7,  # not given for the test specimen; middle of the paper's 5…11 sweep
        contact_angle=math.radians(45.0),
        engaged_threads=10,
        nut_outer_diameter=50e-3,
        screw_free_length=0.1,
        screw_material=steel,
        roller_material=steel,
        nut_material=steel,
        gear=GearGeometry(ring_teeth=70, roller_teeth=14, module=0.5e-3, face_width=3e-3),
        masses=MassProperties(
            screw_mass=1.2,
            screw_inertia=_solid_cylinder_inertia(1.2, d_s / 2),
            nut_mass=0.5,
            nut_inertia=0.5 * 0.5 * ((35e-3 / 2) ** 2 + (50e-3 / 2) ** 2),
            roller_mass=roller_mass,
            roller_inertia=_solid_cylinder_inertia(roller_mass, d_r / 2),
            carrier_mass=0.02,
            carrier_inertia=0.02 * ((d_s + d_r) / 2) ** 2,
        ),
        reference="paper 04 base parameters (pitch diameters read from the quoted diameters)",
    )


def _paper05() -> PRSMDesign:
    d, d1, d2 = 12e-3, 36e-3, 60e-3
    material = Material(youngs_modulus=200e9, poisson_ratio=0.27, shear_modulus=85e9)
    roller_mass = 0.06
    return PRSMDesign(
        name="paper05",
        variant="standard",
        screw_diameter=d1,
        roller_diameter=d,
        nut_diameter=d2,
        # Lead 5 mm with n_n = d2/d = 5 starts → 1 mm pitch. The printed lead angle 3° is not
        # atan(5/(π·36)) = 2.53°; the cylinder model uses the printed 3° (docs/validation.md).
        pitch=1e-3,
        screw_starts=5,
        nut_starts=5,
        roller_starts=1,
        n_rollers=10,
        contact_angle=math.radians(45.0),
        engaged_threads=15,
        nut_outer_diameter=80e-3,
        nut_length=0.6,
        screw_free_length=0.3,
        screw_material=material,
        roller_material=material,
        nut_material=material,
        gear=GearGeometry(ring_teeth=100, roller_teeth=20, module=0.6e-3, face_width=4e-3),
        masses=MassProperties(
            screw_mass=3.0,
            screw_inertia=_solid_cylinder_inertia(3.0, d1 / 2),
            nut_mass=5.0,
            nut_inertia=0.5 * 5.0 * ((d2 / 2) ** 2 + (80e-3 / 2) ** 2),
            roller_mass=roller_mass,
            roller_inertia=_solid_cylinder_inertia(roller_mass, d / 2),
            carrier_mass=0.08,
            carrier_inertia=0.08 * ((d1 + d) / 2) ** 2,
        ),
        reference="paper 05 parameter table",
    )


PRESETS = {
    "paper01": _paper01,
    "paper02": _paper02,
    "paper03": _paper03,
    "paper04": _paper04,
    "paper05": _paper05,
}

DEFAULT_PRESET = "paper01"
#: The preset a design of each variant starts from (``design template --variant``): the
#: recirculating PRSM's is paper 03's.
VARIANT_PRESETS = {"standard": DEFAULT_PRESET, "recirculating": "paper03"}


def preset(name: str = DEFAULT_PRESET) -> PRSMDesign:
    """A named design preset.

    Parameters
    ----------
    name : str
        One of :data:`PRESETS` (``paper01`` … ``paper05``).
    """
    if name not in PRESETS:
        raise ParameterError("design", name, f"must be one of {', '.join(sorted(PRESETS))}")
    return PRESETS[name]()

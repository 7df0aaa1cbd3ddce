"""Design files: a :class:`~prsm_health.actuator.design.PRSMDesign` as TOML, and designs by name or path.

A design file holds the fields of :class:`~prsm_health.actuator.design.PRSMDesign` under their own names,
in SI units (m, kg, kg·m², Pa, rad); the nested dataclasses are tables: ``[masses]``,
``[gear]`` (standard variant only), ``[recirculation]`` (recirculating variant only: paper 03's
carrier and cam ring), ``[screw_material]``, ``[roller_material]``, ``[nut_material]``. Optional fields (``None`` in Python) are left out. ``name`` defaults to the
file's stem. See docs/formats.md → Design files.

Design identity: a design travels with its data (a dataset's manifest, a run's scenario, a
model's metadata) as its dict form; :func:`design_fingerprint` names it in a label and
:func:`same_design` compares two. The name is for people; the fingerprint decides.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from pathlib import Path

from prsm_health.core.errors import ParameterError
from prsm_health.core.tomlfile import read_toml, toml_value

from .design import PRESETS, GearGeometry, MassProperties, Material, PRSMDesign, preset
from .recirculation_spec import RECIRCULATION_FIELDS, RecirculationSpec

#: Unit and meaning of every design field, by dotted name below the design (``gear.module``);
#: the material fields apply to each of the three ``*_material`` tables.
FIELDS = {
    "name": ("", "design name"),
    "variant": ("", '"standard" (threaded rollers, ring gears) or "recirculating" (paper 03)'),
    "screw_diameter": ("m", "screw thread pitch diameter d_s"),
    "roller_diameter": ("m", "roller thread pitch diameter d_r"),
    "nut_diameter": ("m", "nut thread pitch diameter d_n = d_s + 2·d_r (within 0.5 %)"),
    "pitch": ("m", "axial thread pitch, common to screw, rollers and nut"),
    "screw_starts": ("", "screw thread starts n_s"),
    "nut_starts": ("", "nut thread starts n_n = n_s (standard: n_n·d_r = n_r·d_n)"),
    "roller_starts": ("", "roller thread starts n_r (0 for recirculating grooved rollers)"),
    "n_rollers": ("", "number of rollers"),
    "contact_angle": ("rad", "thread contact angle β from the radial plane (15°–75°)"),
    "engaged_threads": ("", "thread turns of one roller engaged with the screw"),
    "nut_outer_diameter": ("m", "nut outer diameter"),
    "screw_free_length": ("m", "screw length between its axial bearing and the nut"),
    "screw_bore_diameter": ("m", "screw bore diameter (0: solid screw)"),
    "thread_addendum": ("m", "thread crest height (absent: 0.25·p·tan β)"),
    "roller_profile_radius": ("m", "roller thread profile radius (absent: r_r / cos β)"),
    "nut_length": ("m", "threaded nut length (absent: engaged_threads·pitch)"),
    "reference": ("", "where the numbers come from"),
    "material.youngs_modulus": ("Pa", "Young's modulus E"),
    "material.poisson_ratio": ("", "Poisson's ratio ν"),
    "material.density": ("kg/m³", "density"),
    "material.shear_modulus": ("Pa", "shear modulus G (absent: E / (2(1 + ν)))"),
    "gear.ring_teeth": ("", "teeth of the nut's internal ring gear z_ring"),
    "gear.roller_teeth": ("", "teeth of the roller-end gear z_roller (z_ring/z_roller = d_n/d_r)"),
    "gear.module": ("m", "gear module"),
    "gear.pressure_angle": ("rad", "standard pressure angle α0 (10°–35°)"),
    "gear.face_width": ("m", "roller gear face width"),
    "gear.addendum_coefficient": ("", "tooth addendum in modules"),
    "gear.dedendum_coefficient": ("", "tooth dedendum in modules"),
    "masses.screw_mass": ("kg", "screw mass"),
    "masses.screw_inertia": ("kg·m²", "screw polar moment of inertia"),
    "masses.nut_mass": ("kg", "nut mass"),
    "masses.nut_inertia": ("kg·m²", "nut polar moment of inertia"),
    "masses.roller_mass": ("kg", "mass of one roller"),
    "masses.roller_inertia": ("kg·m²", "polar moment of inertia of one roller"),
    "masses.carrier_mass": ("kg", "carrier mass"),
    "masses.carrier_inertia": ("kg·m²", "carrier polar moment of inertia"),
    **{f"recirculation.{k}": v for k, v in RECIRCULATION_FIELDS.items()},
}

_TABLES = {
    "masses": MassProperties,
    "gear": GearGeometry,
    "screw_material": Material,
    "roller_material": Material,
    "nut_material": Material,
    "recirculation": RecirculationSpec,
}
#: Tables added to the design after designs had fingerprints: absent (None, or every field
#: left to its rule) they leave a design's identity as it was.
_ABSENT_IS_NONE = ("recirculation",)


def field_info(dotted: str) -> tuple[str, str]:
    """(unit, meaning) of a dotted design field (``gear.module``, ``nut_material.density``)."""
    head, _, tail = dotted.partition(".")
    if head.endswith("_material"):
        dotted = f"material.{tail}"
    return FIELDS.get(dotted, ("", ""))


def load_design(design: str | Path | dict | PRSMDesign, *, base: Path | None = None) -> PRSMDesign:
    """A design from a preset name, a design TOML file, a dict or a design.

    Parameters
    ----------
    design : str, Path, dict or PRSMDesign
        A preset name (``paper01`` … ``paper05``), a path to a ``.toml`` design file, the dict
        form of :meth:`PRSMDesign.to_dict` or a design (returned as is).
    base : Path, optional
        Folder a relative path is resolved against (default: the working directory).
    """
    if isinstance(design, PRSMDesign):
        return design
    if isinstance(design, dict):
        return PRSMDesign.from_dict(design)
    if isinstance(design, str) and design in PRESETS:
        return preset(design)
    if not isinstance(design, (str, Path)):
        raise ParameterError(
            "design", design, "must be a preset name, a design TOML file or a table"
        )
    path = Path(design)
    if not path.is_absolute() and base is not None:
        path = Path(base) / path
    if path.suffix != ".toml" and not path.exists():
        raise ParameterError(
            "design",
            str(design),
            f"must be one of {', '.join(sorted(PRESETS))} or a design TOML file (*.toml)",
        )
    data = read_toml(path, "design file")
    data.setdefault("name", path.stem)
    return PRSMDesign.from_dict(data)


def design_reference(design: str | Path | dict | PRSMDesign, *, base: Path | None = None):
    """How data carries a design (a recipe, a column map, a manifest): a preset name as is,
    anything else — a design file, relative to ``base``, a dict, a PRSMDesign — as the checked
    design's dict form, so the data holds the design itself, never a path."""
    if isinstance(design, str) and design in PRESETS:
        return design
    return load_design(design, base=base).to_dict()


def design_to_toml(design: PRSMDesign, *, comments: bool = True) -> str:
    """TOML text that :func:`load_design` reads back to an equal design.

    Parameters
    ----------
    design : PRSMDesign
    comments : bool
        Follow every value with a comment giving its unit and meaning.
    """
    data = design.to_dict()
    tables = {key: data.pop(key) for key in _TABLES if data.get(key) is not None}
    data = {k: v for k, v in data.items() if k not in _TABLES}
    lines = _toml_lines(data, "", comments)
    for table, values in tables.items():
        lines += ["", f"[{table}]"] + _toml_lines(values, table, comments)
    return "\n".join(lines) + "\n"


def design_toml_tables(design: PRSMDesign, prefix: str) -> list[str]:
    """The design as TOML tables under ``[prefix]`` (a scenario's ``[design]``), no comments."""
    data = design.to_dict()
    tables = {key: data.pop(key) for key in _TABLES if data.get(key) is not None}
    data = {k: v for k, v in data.items() if k not in _TABLES}
    lines = [f"[{prefix}]"] + _toml_lines(data, "", False)
    for table, values in tables.items():
        lines += ["", f"[{prefix}.{table}]"] + _toml_lines(values, table, False)
    return lines


def _toml_lines(values: dict, table: str, comments: bool) -> list[str]:
    rows = [(k, toml_value(v)) for k, v in values.items() if v is not None]
    width = max((len(f"{k} = {v}") for k, v in rows), default=0)
    out = []
    for key, text in rows:
        line = f"{key} = {text}"
        if comments:
            unit, meaning = field_info(f"{table}.{key}" if table else key)
            note = f"[{unit}] {meaning}" if unit else meaning
            line = f"{line:<{width}}  # {note}".rstrip(" #")
        out.append(line)
    return out


def design_rows(design: PRSMDesign) -> list[tuple[str, object, str]]:
    """(dotted field, value, unit) of every field, ``None`` shown as "–" (for tables)."""
    rows = []

    def walk(values: dict, prefix: str) -> None:
        for key, value in values.items():
            dotted = f"{prefix}{key}"
            if isinstance(value, dict):
                walk(value, f"{dotted}.")
            else:
                rows.append((dotted, "–" if value is None else value, field_info(dotted)[0]))

    walk(design.to_dict(), "")
    return rows


# ---------------------------------------------------------------------- identity
#: Fields that describe a design to people, not the mechanism: left out of its identity.
IDENTITY_IGNORES = ("name", "reference")
#: Hex digits of :func:`design_fingerprint` (64 bits: no collision among any realistic number
#: of designs, short enough for a label column).
FINGERPRINT_LENGTH = 16


def canonical_design(design: str | Path | dict | PRSMDesign) -> dict:
    """The design's identity as a plain dict: its dict form without :data:`IDENTITY_IGNORES`.

    Rebuilt through :meth:`PRSMDesign.from_dict`, so an integer given for a float field reads
    as the float (``pitch = 2`` and ``pitch = 2.0`` are one design), and -0.0 as 0.0.

    Parameters
    ----------
    design : PRSMDesign, preset name, design TOML file or dict form
        Anything :func:`load_design` reads.
    """
    data = PRSMDesign.from_dict(load_design(design).to_dict()).to_dict()
    for key in IDENTITY_IGNORES:
        data.pop(key, None)
    for key in _ABSENT_IS_NONE:
        if not any(v is not None for v in (data.get(key) or {}).values()):
            data.pop(key, None)
    return _plain_zero(data)


def _plain_zero(values: dict) -> dict:
    # -0.0 == 0.0 but json writes "-0.0": one design, one text
    return {
        k: _plain_zero(v) if isinstance(v, dict) else (v + 0.0 if isinstance(v, float) else v)
        for k, v in values.items()
    }


def design_fingerprint(design: str | Path | dict | PRSMDesign) -> str:
    """Short hex SHA-256 of the design's identity (:func:`canonical_design` as sorted JSON).

    Two designs have one fingerprint exactly when :func:`same_design` holds. Floats are hashed
    as written by :func:`repr` (the shortest text that reads back to the same float64), so a
    design keeps its fingerprint through every form it travels in — TOML, JSON, dict, Parquet.

    Parameters
    ----------
    design : PRSMDesign, preset name, design TOML file or dict form

    Returns
    -------
    str
        :data:`FINGERPRINT_LENGTH` lowercase hex digits.
    """
    text = json.dumps(canonical_design(design), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:FINGERPRINT_LENGTH]


def same_design(a: str | Path | dict | PRSMDesign, b: str | Path | dict | PRSMDesign) -> bool:
    """Whether two designs are the same mechanism: equal :func:`canonical_design` dicts.

    Names and references are ignored (``==`` on :class:`PRSMDesign` compares the name too).
    Floats compare exactly, not within a tolerance: every form a design travels in round-trips
    float64 exactly, so a design read back is bit-equal to itself, and an exact rule is the one
    a fingerprint (a hash, which cannot be tolerant) agrees with — two designs are the same
    exactly when their fingerprints are.
    """
    return canonical_design(a) == canonical_design(b)


def labelled_same_design(
    name: str | None, fingerprint: str | None, other_name: str | None, other_fingerprint: str | None
) -> bool | None:
    """Whether two things labelled with a design (a recording, a history, a model) are of one
    design: by fingerprint where both carry one — the name is for people and may be reused —
    else by name; None when either names no design at all (nothing to compare)."""
    if fingerprint is not None and other_fingerprint is not None:
        return fingerprint == other_fingerprint
    if name is None or other_name is None:
        return None
    return name == other_name


def design_of(source, name: str | None = None) -> PRSMDesign | None:
    """The design of a run: its scenario's design, else the preset its operating point names,
    else None.

    Parameters
    ----------
    source : Run or dict
        A :class:`~prsm_health.core.run.Run` (its ``scenario`` and ``operating.design`` are
        read) or a run's scenario dict. A simulated run's scenario holds ``design`` (a preset
        name or the full dict form); a dataset's run holds it too, and under ``recipe``.
    name : str, optional
        The run's design name, when ``source`` is a scenario dict.

    Returns
    -------
    PRSMDesign or None
        None when the run carries no design and names no preset (an imported rig, a design
        known only by name): the caller decides what that means.
    """
    if hasattr(source, "scenario"):
        source, name = source.scenario, source.operating.design if name is None else name
    scenario = source if isinstance(source, Mapping) else {}
    recipe = scenario.get("recipe")
    for ref in (
        scenario.get("design"),
        recipe.get("design") if isinstance(recipe, Mapping) else None,
    ):
        if isinstance(ref, Mapping):
            return PRSMDesign.from_dict(dict(ref))
        if isinstance(ref, PRSMDesign):
            return ref
        if isinstance(ref, str) and ref in PRESETS:
            return preset(ref)
    if isinstance(name, str) and name in PRESETS:
        return preset(name)
    return None


__all__ = [
    "FIELDS",
    "canonical_design",
    "design_fingerprint",
    "design_of",
    "design_reference",
    "design_rows",
    "design_to_toml",
    "field_info",
    "labelled_same_design",
    "load_design",
    "same_design",
]

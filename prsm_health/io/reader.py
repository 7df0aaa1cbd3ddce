"""The one recording reader: a file or its bytes (MCAP, Parquet, CSV, Arrow IPC), through a
column map when given one, with the derivable channels added (:mod:`.derived`), and the
reader's warnings collected as sentences (:class:`Recording`) — with one line per channel whose
declared unit the actuator's physics doubts (:mod:`prsm_health.signals.unit_checks`), naming
the file's column and the likely unit, so import, ``diagnose`` and the service all say it.

:func:`read_with_warnings` does the work; :func:`prsm_health.io.read_recording` and
:func:`prsm_health.io.read_recording_bytes` are it for callers that want the run only (the
warnings are then raised again as Python warnings, as each format's reader raises them).
"""

from __future__ import annotations

import tempfile
import threading
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from prsm_health.core.channels import UNITS as CHANNEL_UNITS
from prsm_health.core.errors import PRSMHealthError
from prsm_health.core.run import Run
from prsm_health.signals.unit_checks import unit_mismatches

from .column_map import UNITS, ColumnMap, apply_column_map, load_column_map, unit_slips
from .derived import derive_channels

#: File suffix → format.
SUFFIXES = {".mcap": "mcap", ".parquet": "parquet", ".csv": "csv"}
#: Formats of recordings held in memory.
BYTE_FORMATS = ("arrow", "parquet", "mcap", "csv")
#: Formats a column map applies to (an MCAP recording of this project's layout carries the
#: contract channels in SI already).
MAPPED_FORMATS = ("csv", "parquet")

# warnings.catch_warnings changes process-wide state: one recording is read under it at a time.
_warnings_lock = threading.Lock()


@dataclass(frozen=True)
class Recording:
    """A recording as read: the run, the reader's warnings and the channels it derived.

    Attributes
    ----------
    run : Run
    warnings : tuple of str
        The readers' warnings as sentences (a truncated MCAP recording read up to the damage,
        a time axis that looks like milliseconds, …), naming the recording as the caller did.
    derived : tuple of str
        Channels derived from others (:func:`~prsm_health.io.derived.derive_channels`).
    """

    run: Run
    warnings: tuple[str, ...] = ()
    derived: tuple[str, ...] = ()
    categories: tuple[type[Warning], ...] = field(default=(), repr=False, compare=False)

    def warn(self, stacklevel: int = 2) -> None:
        """Raise the collected warnings again, each with its category."""
        for text, category in zip(self.warnings, self.categories):
            warnings.warn(text, category, stacklevel=stacklevel + 1)


def read_with_warnings(
    source: str | Path | bytes,
    *,
    fmt: str | None = None,
    name: str | None = None,
    column_map: ColumnMap | str | Path | None = None,
) -> Recording:
    """Read a recording: the run (channels in SI, the derivable ones added), the warnings.

    Parameters
    ----------
    source : path or bytes
        A ``.mcap``, ``.parquet`` or ``.csv`` file, or a recording held in memory (``fmt``
        then says which).
    fmt : {"mcap", "parquet", "csv", "arrow"}, optional
        Default: from the file suffix. Required for bytes.
    name : str, optional
        How messages and warnings name the recording instead of its path (an upload's file
        name; a server's temporary path never appears). Default: the path, or "recording".
    column_map : ColumnMap, path of a MAP.toml, or None
        How a CSV or Parquet file names and scales its columns (docs/import.md); time then
        starts at 0. Ignored for MCAP. None: contract column names in SI (docs/formats.md).

    Raises
    ------
    PRSMHealthError
        Missing or unreadable file, unsupported format, a map the file does not fit (naming
        the file and the column), a cell that is not a number (naming the file, the column
        and the row).
    """
    spec = load_column_map(column_map) if isinstance(column_map, (str, Path)) else column_map
    if isinstance(source, (bytes, bytearray, memoryview)):
        where = name or "recording"
        if fmt not in BYTE_FORMATS:
            raise PRSMHealthError(
                f"{where}: unsupported format {fmt!r} (use {', '.join(BYTE_FORMATS)})"
            )
        path = None
    else:
        path = Path(source)
        where = name or str(path)
        if fmt is None:
            if not path.exists():
                raise PRSMHealthError(f"{where}: no such file")
            fmt = SUFFIXES.get(path.suffix.lower())
            if fmt is None:
                raise PRSMHealthError(
                    f"{where}: unsupported file type {path.suffix.lower()!r} "
                    f"(use {', '.join(SUFFIXES)})"
                )
    with _warnings_lock, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UserWarning)
        run, hidden = _read(source if path is None else path, fmt, where, spec)
    run, derived = derive_channels(run)
    texts, categories = [], []
    for w in caught:
        text = _named(str(w.message), hidden, where)
        if issubclass(w.category, UserWarning):
            texts.append(text)
            categories.append(w.category)
        else:  # not about the recording (a library's deprecation): passed on as it came
            warnings.warn_explicit(text, w.category, w.filename, w.lineno)
    notes = _unit_notes(run, spec if fmt in MAPPED_FORMATS else None, where)
    texts += notes
    categories += [UserWarning] * len(notes)
    return Recording(run, tuple(texts), derived, tuple(categories))


def _unit_notes(run: Run, spec: ColumnMap | None, where: str) -> list[str]:
    """One sentence per channel whose declared unit looks off by a unit slip, naming the
    file's column, its declared unit and the likely one (``spec``: the map applied, if any)."""
    declared = {}  # channel → (file column, its unit); drive_torque may come from a current
    for name in run.channels:
        if spec is None:
            declared[name] = (name, CHANNEL_UNITS.get(name))
        else:
            key = "motor_current" if name == "drive_torque" else name
            key = key if key in spec.columns else name
            if key in spec.columns:
                column = spec.columns[key]
                declared[name] = (column, spec.units[column])
    slips = {name: unit_slips(unit) for name, (_, unit) in declared.items() if unit in UNITS}
    notes = []
    for m in unit_mismatches(run, slips=slips):
        column, unit = declared.get(m.channel, (None, None))
        likely = slips.get(m.channel, {}).get(m.factor)
        notes.append(f"{where}: {m.sentence(column, unit, likely)}")
    return notes


def _read(source, fmt: str, where: str, spec: ColumnMap | None) -> tuple[Run, str | None]:
    """The format's reader; also the path its messages use that must read as ``where``."""
    hidden = str(source) if isinstance(source, Path) else None
    try:
        if spec is not None and fmt in MAPPED_FORMATS:
            from .frames import read_frame

            return apply_column_map(read_frame(source, fmt, where), spec, where), hidden
        if fmt == "csv":
            from .csv import read_csv

            return read_csv(source, name=where), hidden
        if fmt == "parquet":
            from .parquet import read_run_parquet

            return read_run_parquet(source, name=where), hidden
        if fmt == "arrow":
            from .arrow import read_run_arrow

            return read_run_arrow(source, where), hidden
        from .mcap import read_mcap

        if isinstance(source, Path):
            return read_mcap(source), hidden
        # The MCAP reader scans files: bytes go through a private temporary file.
        with tempfile.TemporaryDirectory(prefix="prsm-health-mcap-") as tmp:
            path = Path(tmp) / "recording.mcap"
            path.write_bytes(source)
            hidden = str(path)
            return read_mcap(path), hidden
    except PRSMHealthError as exc:
        if hidden is not None and hidden != where:
            exc.args = (_named(str(exc), hidden, where),)
        raise exc.with_traceback(None) from None


def _named(text: str, hidden: str | None, where: str) -> str:
    return text.replace(hidden, where) if hidden and hidden != where else text

"""Safe persistence of trained models: skops archives with a version-checked JSON header.

- :func:`save_model`: a skops archive of a model (an estimator or a dict of them) plus a JSON
  member with the package versions, the save time and user metadata; written atomically.
- :func:`load_model`: checks the header and the prsm_health / scikit-learn versions before
  anything is instantiated, and only loads classes from scikit-learn, numpy and
  :mod:`prsm_health.diagnostics.estimators` (``_TRUSTED_ROOTS``). A model from another major.minor version
  raises :class:`~prsm_health.core.errors.ModelVersionError`. A file loaded again in the same
  process is not rebuilt: the caller gets a deep copy of the model first rebuilt from the same
  bytes.
"""

from __future__ import annotations

import copy
import importlib
import io
import json
import re
import warnings
import zipfile
from datetime import datetime, timezone
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import sklearn

from prsm_health.core.atomic import write_atomic
from prsm_health.core.errors import ModelVersionError, ParameterError, PRSMHealthError, require
from prsm_health.core.jsonable import json_ready
from prsm_health.core.version import __version__

__all__ = ["load_model", "save_model"]

_HEADER_NAME = "prsm_health.json"
_FORMAT = "prsm_health-model"
_FORMAT_VERSION = 1
_RESERVED_METADATA = ("versions", "saved_at")
# Module roots whose classes a model file may instantiate; anything else is refused.
_TRUSTED_ROOTS = ("sklearn", "numpy", "prsm_health.diagnostics.estimators")
# Where classes of older model files live now: 0.1 files written before the package was laid
# out in layer folders name ``prsm_health.estimators``; their schema is read with the new path.
_MOVED_MODULES = {'"prsm_health.estimators"': '"prsm_health.diagnostics.estimators"'}
_SKOPS_SCHEMA = "schema.json"


def _current_versions() -> dict[str, str]:
    import skops

    return {
        "prsm_health": __version__,
        "scikit-learn": sklearn.__version__,
        "numpy": np.__version__,
        "skops": skops.__version__,
    }


def _major_minor(version: str) -> tuple[int, int] | None:
    match = re.match(r"\s*(\d+)\.(\d+)", str(version))
    return (int(match[1]), int(match[2])) if match else None


def _in_trusted_root(name: str) -> bool:
    return any(name == root or name.startswith(root + ".") for root in _TRUSTED_ROOTS)


def _resolve(name: str):
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr, None)
            if obj is None:
                return None
        return obj
    return None


def _is_trusted(name: str) -> bool:
    """Trust only classes defined in scikit-learn, numpy or :mod:`prsm_health.diagnostics.estimators`.

    Functions are refused even from those packages: skops may call a loaded callable with
    arguments from the file (numpy alone has functions that execute strings).
    """
    if not _in_trusted_root(name):
        return False
    obj = _resolve(name)
    return isinstance(obj, type) and _in_trusted_root(f"{obj.__module__}.{obj.__qualname__}")


def _with_current_module_paths(payload: bytes) -> bytes:
    """``payload`` with the class paths of moved modules rewritten in its skops schema."""
    with zipfile.ZipFile(io.BytesIO(payload)) as zf:
        schema = zf.read(_SKOPS_SCHEMA).decode()
        if not any(old in schema for old in _MOVED_MODULES):
            return payload
        for old, new in _MOVED_MODULES.items():
            schema = schema.replace(old, new)
        out = io.BytesIO()
        with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as rewritten:
            for info in zf.infolist():
                member = schema.encode() if info.filename == _SKOPS_SCHEMA else zf.read(info)
                rewritten.writestr(info, member)
    return out.getvalue()


def _refused_types(payload: bytes) -> tuple[list[str], list[str]]:
    import skops.io as sio

    untrusted = sio.get_untrusted_types(data=payload)
    return untrusted, [t for t in untrusted if not _is_trusted(t)]


def _bundle_bytes(model, header: dict) -> bytes:
    """skops payload of ``model`` with the JSON header as an extra zip member."""
    import skops.io as sio

    buffer = io.BytesIO(sio.dumps(model, compression=zipfile.ZIP_DEFLATED))
    # skops ignores members it does not know, so the file stays loadable by skops itself;
    # the header is plain JSON, readable before anything is instantiated.
    with zipfile.ZipFile(buffer, "a", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(_HEADER_NAME, json.dumps(json_ready(header), indent=1))
    return buffer.getvalue()


def save_model(path, model, *, metadata: dict) -> Path:
    """Save a model (an estimator or a dict of them) with versions and metadata.

    The file is a skops archive of ``model`` plus a JSON member ``prsm_health.json`` with the
    prsm_health, scikit-learn, numpy and skops versions, the save time and ``metadata``.
    It is written to a temporary file in the target directory and renamed, so a reader never
    sees a partial file.

    Parameters
    ----------
    path : str or Path
        Destination file (conventionally ``*.skops``); replaced if it exists.
    model : estimator or dict
        E.g. ``{"clearance": ClearanceEstimator, "fault_class": FaultClassifier}``. Must
        contain only types :func:`load_model` trusts (classes from scikit-learn, numpy and
        :mod:`prsm_health.diagnostics.estimators`, plus builtins).
    metadata : dict
        JSON-serialisable user metadata: feature names, training data description, metrics…
        The keys ``versions`` and ``saved_at`` are reserved.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ParameterError
        Metadata that is not a JSON-serialisable dict or uses a reserved key.
    PRSMHealthError
        A model holding types that :func:`load_model` would refuse; an unwritable path.
    """
    path = Path(path)
    require(isinstance(metadata, dict), "metadata", type(metadata).__name__, "must be a dict")
    reserved = [k for k in _RESERVED_METADATA if k in metadata]
    require(not reserved, "metadata", reserved, "keys 'versions' and 'saved_at' are reserved")
    try:
        json.dumps(json_ready(metadata))
    except (TypeError, ValueError) as err:
        raise ParameterError("metadata", "…", f"must be JSON-serialisable ({err})") from err
    header = {
        "format": _FORMAT,
        "format_version": _FORMAT_VERSION,
        "versions": _current_versions(),
        "saved_at": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "metadata": metadata,
    }
    data = _bundle_bytes(model, header)
    _, refused = _refused_types(data)
    if refused:
        raise PRSMHealthError(
            f"{path}: cannot save a model holding types load_model would refuse: "
            + ", ".join(refused)
        )
    write_atomic(path, data)
    return path


def _not_a_model(path, reason) -> PRSMHealthError:
    return PRSMHealthError(f"{path}: not a prsm_health model file ({reason})")


def load_model(path, *, allow_version_mismatch: bool = False) -> tuple[Any, dict]:
    """Load a model saved by :func:`save_model`, safely.

    The JSON header is read and checked before anything is instantiated; only classes from
    scikit-learn, numpy and :mod:`prsm_health.diagnostics.estimators` (and skops' default-trusted
    builtins) are loaded.

    Parameters
    ----------
    path : str or Path
        Model file.
    allow_version_mismatch : bool, default False
        Load (with a warning) a model saved by another prsm_health or scikit-learn
        major.minor version. Predictions of such a model are not guaranteed to be right.

    Returns
    -------
    model : estimator or dict
        What was saved.
    metadata : dict
        The user metadata plus ``versions`` (dict of package versions at save time) and
        ``saved_at`` (ISO 8601 UTC).

    Raises
    ------
    ModelVersionError
        Saved with another major.minor version of prsm_health or scikit-learn (the numpy
        version is recorded but not checked: its array format is stable).
    PRSMHealthError
        Unreadable, corrupt or foreign file; untrusted types in the file.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as err:
        raise PRSMHealthError(f"{path}: cannot read model file ({err.strerror})") from err
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            header = json.loads(zf.read(_HEADER_NAME))
    except zipfile.BadZipFile as err:
        raise _not_a_model(path, "not a zip archive") from err
    except KeyError as err:
        raise _not_a_model(path, f"no {_HEADER_NAME} header") from err
    except (ValueError, OSError, RuntimeError, zipfile.LargeZipFile) as err:
        raise _not_a_model(path, f"unreadable header: {err}") from err
    if not isinstance(header, dict) or header.get("format") != _FORMAT:
        raise _not_a_model(path, "unknown header format")
    if header.get("format_version") != _FORMAT_VERSION:
        raise _not_a_model(path, f"unsupported format version {header.get('format_version')}")
    versions = header.get("versions")
    metadata = header.get("metadata")
    if not isinstance(versions, dict) or not isinstance(metadata, dict):
        raise _not_a_model(path, "header without versions or metadata")

    current = _current_versions()
    mismatched = [
        package
        for package in ("prsm_health", "scikit-learn")
        if _major_minor(versions.get(package, "")) is None
        or _major_minor(versions[package]) != _major_minor(current[package])
    ]
    if mismatched:
        saved = " and ".join(f"{p} {versions.get(p, '(unknown)')}" for p in mismatched)
        running = " and ".join(f"{p} {current[p]}" for p in mismatched)
        message = (
            f"{path}: model saved with {saved}, running {running}; retrain it or pass "
            "allow_version_mismatch=True"
        )
        if not allow_version_mismatch:
            raise ModelVersionError(message)
        warnings.warn(message, UserWarning, stacklevel=2)

    # a copy: the caller may change its model (refit it) without changing the next caller's
    model = copy.deepcopy(_rebuilt(str(path), data))
    return model, {**metadata, "versions": versions, "saved_at": header.get("saved_at")}


@lru_cache(maxsize=16)
def _rebuilt(path: str, data: bytes):
    """The model in a model file's bytes, its types checked first; the last 16 kept for the
    process, by file and content: auditing and rebuilding the shipped model's two files takes
    ≈ 3–5 s, a deep copy of them ≈ 0.1 s, and one process (a test session, a script diagnosing
    recording after recording with the default model) may load them again and again."""
    import skops.io as sio

    try:
        data = _with_current_module_paths(data)
        untrusted, refused = _refused_types(data)
    except Exception as err:  # a corrupt skops schema can fail in many ways
        raise _not_a_model(path, f"corrupt model payload: {err}") from err
    if refused:
        raise PRSMHealthError(f"{path}: refusing to load untrusted types: {', '.join(refused)}")
    try:
        return sio.loads(data, trusted=untrusted)
    except Exception as err:  # corrupt arrays or schema: any exception means "unreadable"
        raise _not_a_model(path, f"corrupt model payload: {type(err).__name__}: {err}") from err

"""Identifiers — an asset (unit) and a recording — the one rule a given id follows, and the one
recording id made from content (:func:`content_id`). The rule for given ids:
1–128 characters, letters, digits, ``.``, ``_``, ``:`` or ``-``, starting with a letter or
digit (safe as a file name, a URL path segment and a database key)."""

#: An asset id (the CLI's ``--asset``, the service's ``asset_id``).
ASSET_ID_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._:-]{0,127}$"
#: A recording id (the service's ``recording_id``): the same rule.
RECORDING_ID_PATTERN = ASSET_ID_PATTERN
#: The rule in words, for error messages.
ASSET_ID_RULE = (
    "1–128 characters: letters, digits, '.', '_', ':' or '-', starting with a letter or digit"
)

#: Hex digits of a recording id made from content (64 bits: collisions among a unit's
#: recordings are out of reach).
CONTENT_ID_LENGTH = 16


def content_id(*parts) -> str:
    """The one recording id made from content: SHA-256 over each part followed by a NUL byte,
    its first :data:`CONTENT_ID_LENGTH` hex digits. A part is ``bytes`` or a file path
    (``str`` or :class:`~pathlib.Path`, read in chunks); None parts are skipped. A file
    diagnosed by ``prsm-health diagnose --asset`` and the same file uploaded to the service
    (or sent as a body) get the same id, whatever its name.

    Raises
    ------
    PRSMHealthError
        A file that cannot be read (the message names it).
    """
    import hashlib
    from pathlib import Path

    from .errors import PRSMHealthError

    digest = hashlib.sha256()
    for part in parts:
        if part is None:
            continue
        if isinstance(part, (bytes, bytearray, memoryview)):
            digest.update(part)
        else:
            try:
                with open(Path(part), "rb") as f:
                    while chunk := f.read(1 << 20):
                        digest.update(chunk)
            except OSError as err:
                raise PRSMHealthError(f"{part}: cannot read ({err.strerror})") from None
        digest.update(b"\0")
    return digest.hexdigest()[:CONTENT_ID_LENGTH]


def run_content_id(run) -> str:
    """The recording id of a :class:`~prsm_health.core.run.Run` that came without a file (a
    JSON body): :func:`content_id` over its sample rate and first sample time, then each
    channel's name and float64 samples in name order."""
    import numpy as np

    parts = [f"{float(run.sample_rate)!r} {float(run.time[0])!r}".encode()]
    for name in sorted(run.channels):
        parts += [name.encode(), np.ascontiguousarray(run.channels[name], dtype=float).tobytes()]
    return content_id(*parts)

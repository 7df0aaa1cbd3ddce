"""Identifiers a user gives — an asset (unit) and a recording — and the one rule they follow:
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

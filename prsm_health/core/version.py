"""The package's version, read once from its installed metadata (pyproject.toml declares it).

Every module that writes the version into a file or a header imports it from here, never from
the package root: the root re-exports every layer lazily, so a layer importing it would depend,
through it, on the layers above.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("prsm_health")
except PackageNotFoundError:  # a source tree on sys.path, never installed: no metadata to read
    __version__ = "0+unknown"

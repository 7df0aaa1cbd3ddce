"""Vendor the dashboard's JavaScript plotting library into the package (run by hand, or
``make vendor``; the files it writes are committed).

``npm pack uplot@VERSION`` in a temporary directory fetches the package tarball from the npm
registry; its integrity (sha512, Subresource Integrity form) is checked against what
``npm view`` reports, and ``dist/uPlot.iife.min.js``, ``dist/uPlot.min.css`` and ``LICENSE`` are
extracted into ``prsm_health/apps/service/static/vendor/uplot/`` with a ``VENDORED.json`` recording
name, version, licence, tarball URL, integrity and the sha256 of each file written. Nothing is
downloaded at run time: the service serves these files from the package.

    python tools/release/vendor_js.py            # uplot@1.6.32
    python tools/release/vendor_js.py --check    # verify the committed files against VENDORED.json
"""

from __future__ import annotations

import argparse
import base64
import hashlib
import json
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

NAME = "uplot"
VERSION = "1.6.32"
#: tarball member → file name in the vendor directory
FILES = {
    "package/dist/uPlot.iife.min.js": "uPlot.iife.min.js",
    "package/dist/uPlot.min.css": "uPlot.min.css",
    "package/LICENSE": "LICENSE",
}
ROOT = Path(__file__).resolve().parents[2]
TARGET = ROOT / "prsm_health" / "apps" / "service" / "static" / "vendor" / "uplot"


def _npm(*args: str, cwd: Path) -> str:
    npm = shutil.which("npm")
    if npm is None:
        sys.exit("error: npm not found (install Node.js 18+ with npm)")
    done = subprocess.run(
        [npm, *args], cwd=cwd, capture_output=True, text=True, check=False, timeout=300
    )
    if done.returncode != 0:
        sys.exit(f"error: npm {' '.join(args)} failed:\n{done.stderr.strip()}")
    return done.stdout


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def vendor(name: str, version: str, target: Path) -> dict:
    with tempfile.TemporaryDirectory(prefix="prsm-health-vendor-") as tmp:
        tmp = Path(tmp)
        spec = f"{name}@{version}"
        view = json.loads(
            _npm("view", spec, "--json", "name", "version", "license", "dist", cwd=tmp)
        )
        packed = json.loads(_npm("pack", spec, "--json", cwd=tmp))[0]
        tarball = tmp / packed["filename"]
        data = tarball.read_bytes()
        integrity = "sha512-" + base64.b64encode(hashlib.sha512(data).digest()).decode()
        expected = view["dist"]["integrity"]
        if integrity != expected or packed.get("integrity", expected) != expected:
            sys.exit(f"error: {spec} tarball integrity {integrity} != registry's {expected}")
        target.mkdir(parents=True, exist_ok=True)
        written = {}
        with tarfile.open(tarball, "r:gz") as archive:
            for member, filename in FILES.items():
                content = archive.extractfile(archive.getmember(member)).read()
                (target / filename).write_bytes(content)
                written[filename] = _sha256(content)
    record = {
        "name": view["name"],
        "version": view["version"],
        "license": view["license"],
        "tarball": view["dist"]["tarball"],
        "integrity": integrity,
        "files": written,
        "vendored_by": "tools/release/vendor_js.py",
    }
    (target / "VENDORED.json").write_text(json.dumps(record, indent=2) + "\n")
    return record


def check(target: Path) -> list[str]:
    """Differences between the files in ``target`` and its ``VENDORED.json``."""
    record = json.loads((target / "VENDORED.json").read_text())
    problems = []
    for filename, digest in record["files"].items():
        path = target / filename
        if not path.is_file():
            problems.append(f"{filename}: missing")
        elif _sha256(path.read_bytes()) != digest:
            problems.append(f"{filename}: sha256 differs from VENDORED.json")
    return problems


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", default=VERSION, help=f"uPlot version (default {VERSION})")
    parser.add_argument(
        "--check", action="store_true", help="verify the vendored files, fetch nothing"
    )
    args = parser.parse_args(argv)
    if args.check:
        problems = check(TARGET)
        for problem in problems:
            print(f"error: {problem}", file=sys.stderr)
        return 1 if problems else 0
    record = vendor(NAME, args.version, TARGET)
    print(
        f"vendored {record['name']}@{record['version']} ({record['license']}, "
        f"{record['integrity'][:22]}…) into {TARGET.relative_to(ROOT)}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""The layers of docs/architecture.md: no module imports from a layer above its own.

Checked on the source (every import statement, including those inside functions), so a lazy
import cannot hide an upward dependency.
"""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "prsm_health"

#: Layer of each top-level module or subpackage (docs/architecture.md), lowest first.
LAYERS = {
    "errors": 0,
    "jsonable": 0,
    "channels": 0,
    "run": 0,
    "tomlfile": 0,
    "design": 1,
    "design_files": 1,
    "states": 1,
    "faults": 1,
    "drive_train": 1,
    "kinematics": 1,
    "stiffness": 1,
    "friction": 1,
    "lubrication": 1,
    "recirculating": 1,
    "sensors": 1,
    "instrumentation": 1,
    "spectra": 1,
    "gear_indicators": 1,
    "envelope_analysis": 1,
    "signal_kernels": 1,
    "wear": 1,
    "dynamics": 2,
    "scenario": 2,
    "life": 2,
    "io": 3,
    "mcap": 3,
    "dataset": 3,
    "live": 3,
    "features": 4,
    "estimators": 4,
    "trees": 4,
    "evaluation": 4,
    "persistence": 4,
    "training": 4,
    "diagnosis": 4,
    "prognostics": 4,
    "prognostic_metrics": 4,
    "plots": 4,
    "validation": 4,
    "cli": 5,
    "service": 5,
}


def _top(module: Path) -> str:
    return module.relative_to(PACKAGE).parts[0].removesuffix(".py")


def _imported_tops(module: Path) -> set[str]:
    """Top-level prsm_health modules imported anywhere in ``module``."""
    tree = ast.parse(module.read_text())
    depth = len(module.relative_to(PACKAGE).parts) - 1  # 0 for prsm_health/x.py
    tops = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level == 0:
                parts = (node.module or "").split(".")
                if parts[0] == "prsm_health" and len(parts) > 1:
                    tops.add(parts[1])
                elif parts[0] == "prsm_health":
                    tops.update(a.name for a in node.names)
            elif node.level - 1 == depth:  # relative import resolving to the package root
                tops.add(node.module.split(".")[0] if node.module else None)
                if not node.module:
                    tops.update(a.name for a in node.names)
            elif node.level - 1 < depth:  # inside its own subpackage
                tops.add(_top(module))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if parts[0] == "prsm_health" and len(parts) > 1:
                    tops.add(parts[1])
    tops.discard(None)
    return tops


MODULES = sorted(p for p in PACKAGE.rglob("*.py") if p.name != "__init__.py" or p.parent != PACKAGE)


def test_every_module_has_a_layer():
    assert {_top(m) for m in MODULES} <= set(LAYERS), {_top(m) for m in MODULES} - set(LAYERS)


@pytest.mark.parametrize("module", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_import_from_a_layer_above(module):
    own = LAYERS[_top(module)]
    above = {t: LAYERS.get(t) for t in _imported_tops(module) if LAYERS.get(t, -1) > own}
    assert not above, f"{module.relative_to(PACKAGE)} (layer {own}) imports {above}"

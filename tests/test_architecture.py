"""The house in layers (docs/architecture.md), read from the package's own folders and imports.

- The layers are the top folders of ``prsm_health``, in the order ``prsm_health.LAYERS``
  declares once; no module sits outside a layer.
- A module imports only from its own layer and the layers below (every import statement,
  including those inside functions, so a lazy import cannot hide an upward dependency).
- No import cycle between modules, lazy imports included.
- A module over ~800 lines is flagged for review: it is split by job, or its one job is named
  below. The number is a review flag, not a target: a module is never squeezed under it
  (shortened comments, merged lines) — the rule is one job per module, length follows.
"""

import ast
from pathlib import Path

import pytest

import prsm_health

PACKAGE = Path(prsm_health.__file__).resolve().parent
ROOT = PACKAGE.parent
LAYERS = prsm_health.LAYERS
#: The review flag (not a target to fit under): a longer module gets a look at its jobs.
MAX_LINES = 800

#: Modules over MAX_LINES that each do one job, and which.
ONE_JOB = {
    "physics/stiffness/gear_mesh.py": "potential-energy mesh stiffness of one gear pair (its "
    "checked parameters, contact path and mesh cycle; the tooth is in gear_tooth.py)",
    "physics/stiffness/cylinder.py": "paper 05's electric-cylinder deformation model",
    "actuator/design.py": "the PRSM design dataclasses, their validation and the presets",
    "diagnostics/estimators.py": "the scikit-learn estimators of a diagnosis model",
    "simulation/dynamics/_kernels.py": "the numba right-hand side and RK4 of the PRSM model",
}

MODULES = sorted(p for p in PACKAGE.rglob("*.py") if p != PACKAGE / "__init__.py")


def _dotted(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


DOTTED = {_dotted(p): p for p in [*MODULES, PACKAGE / "__init__.py"]}


def _imports(module: Path) -> set[str]:
    """Dotted names of the prsm_health modules ``module`` imports anywhere (submodules named
    in ``from package import submodule`` count as the submodule)."""
    tree = ast.parse(module.read_text())
    own = _dotted(module).split(".")
    base = own if module.name == "__init__.py" else own[:-1]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                target = ".".join(base[: len(base) - node.level + 1] + [node.module or ""])
            else:
                target = node.module or ""
            target = target.rstrip(".")
            if not target.startswith("prsm_health"):
                continue
            subs = [f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in DOTTED]
            found.update(subs or [target])
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith("prsm_health"))
    return {name for name in found if name in DOTTED}


def _layer(dotted: str) -> str | None:
    parts = dotted.split(".")
    return parts[1] if len(parts) > 1 else None


def test_layers_are_the_folders():
    folders = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
    loose = sorted(p.name for p in PACKAGE.glob("*.py") if p.name != "__init__.py")
    assert folders == set(LAYERS), (folders ^ set(LAYERS), "a folder that is no layer, or back")
    assert not loose, f"modules outside every layer: {loose}"


@pytest.mark.parametrize("module", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_import_from_a_layer_above(module):
    own = LAYERS.index(_layer(_dotted(module)))
    above = {
        name
        for name in _imports(module)
        if _layer(name) is not None and LAYERS.index(_layer(name)) > own
    }
    assert not above, f"{module.relative_to(PACKAGE)} ({LAYERS[own]}) imports {sorted(above)}"


def test_no_import_cycle():
    graph = {name: _imports(path) - {name} for name, path in DOTTED.items()}
    # A package's __init__ importing its own submodules is how it re-exports them, not a cycle.
    graph = {
        name: {t for t in targets if not t.startswith(name + ".")}
        for name, targets in graph.items()
    }
    index, low, stack, on_stack, cycles = {}, {}, [], set(), []

    def visit(node):  # Tarjan's strongly connected components
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in graph[node]:
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for name in graph:
        if name not in index:
            visit(name)
    assert not cycles, cycles


@pytest.mark.parametrize("module", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_module_does_one_job_or_is_short(module):
    rel = str(module.relative_to(PACKAGE))
    lines = len(module.read_text().splitlines())
    assert lines <= MAX_LINES or rel in ONE_JOB, (
        f"{rel}: {lines} lines, flagged for review: split it by job, or name its one job in "
        "ONE_JOB (do not squeeze it under the flag)"
    )


def test_the_docs_list_the_layers_in_order():
    text = (ROOT / "docs" / "architecture.md").read_text()
    positions = [text.find(f"`{layer}/`") for layer in LAYERS]
    assert all(p >= 0 for p in positions), dict(zip(LAYERS, positions))
    assert positions == sorted(positions), "docs/architecture.md lists the layers out of order"

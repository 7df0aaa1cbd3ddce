"""The house in layers (docs/architecture.md), read from the package's own folders and imports.

- The layers are the top folders of ``prsm_health``, in the order ``prsm_health.LAYERS``
  declares once; no module sits outside a layer.
- A module imports only from its own layer and the layers below. Every import counts: the
  statements (including those inside functions) and the lazy ones — ``import_module`` of a
  name written in the module (a literal, or an f-string from ``__name__``/``__package__``), and
  the name → module maps a lazy re-export (``__getattr__``) imports from. A name computed at
  run time that none of these explains must be listed in :data:`DYNAMIC` with why it stays in
  its layer.
- No layer module imports the package root (``import prsm_health``, ``from prsm_health import
  X``, ``from .. import X``): the root re-exports every layer lazily, so importing it climbs.
- No import cycle between modules, lazy imports and the root's re-exports included.
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
ROOT_NAME = PACKAGE.name
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
    "simulation/sensors.py": "the sensor models: what each sensor of a profile makes of a truth "
    "signal (its errors, filters, noise), and the delay its filters give",
    "simulation/dynamics/_kernels.py": "the numba right-hand side and RK4 of the PRSM model",
}

#: Modules importing a name computed at run time, and why what they import stays in their layer.
DYNAMIC = {
    "diagnostics/model_files.py": "resolves the class a model file names, refused unless it is "
    "defined in scikit-learn, numpy or prsm_health.diagnostics.estimators (_is_trusted)",
}

MODULES = sorted(p for p in PACKAGE.rglob("*.py") if p != PACKAGE / "__init__.py")


def _dotted(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


DOTTED = {_dotted(p): p for p in [*MODULES, PACKAGE / "__init__.py"]}


# ------------------------------------------------------------------------------ the checker
def _relative(name: str, anchor: str) -> str:
    """``name`` (``.x``, ``..x`` or absolute) resolved against the package ``anchor``, as
    ``importlib.import_module(name, anchor)`` does."""
    level = len(name) - len(name.lstrip("."))
    if not level:
        return name
    base = anchor.split(".")
    base = base[: len(base) - level + 1]
    return ".".join(base + [name[level:]]).rstrip(".")


def _under(prefix: str, known) -> set[str]:
    """The known modules whose dotted name starts with ``prefix`` (an f-string's fixed head),
    but ``__main__`` scripts: ``python -m`` runs them, no name imports them."""
    return {name for name in known if name.startswith(prefix) and not name.endswith("__main__")}


def _dynamic_target(node: ast.expr, own: str, package: str, anchor: ast.expr | None, known):
    """The modules an ``import_module(node, anchor)`` may import, or None when its name is
    computed at run time."""
    names = {"__name__": own, "__package__": package}
    if isinstance(anchor, ast.Name):
        anchor_text = names.get(anchor.id)
    elif isinstance(anchor, ast.Constant) and isinstance(anchor.value, str):
        anchor_text = anchor.value
    else:
        anchor_text = package
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return {_relative(node.value, anchor_text or package)}
    if isinstance(node, ast.JoinedStr) and node.values:
        head = ""
        for part in node.values:
            if isinstance(part, ast.Constant):
                head += part.value
            elif (
                not head
                and isinstance(part, ast.FormattedValue)
                and isinstance(part.value, ast.Name)
                and part.value.id in names
            ):
                head = names[part.value.id]
            else:
                break
        if head.startswith(ROOT_NAME):
            return _under(head, known) or {head}
    return None


def _lazy_maps(tree: ast.Module, package: str) -> set[str]:
    """Module paths held by the module-level dicts of a lazy re-export (``{"name": ".layer.mod"}``
    or ``{"name": (".layer.mod", "attr")}``), resolved against the module's package."""
    found = set()
    for node in tree.body:
        value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
        if not isinstance(value, ast.Dict):
            continue
        for item in value.values:
            parts = item.elts[:1] if isinstance(item, ast.Tuple) else [item]
            for part in parts:
                if isinstance(part, ast.Constant) and isinstance(part.value, str):
                    text = part.value
                    if text.startswith(".") or text.split(".")[0] == ROOT_NAME:
                        found.add(_relative(text, package))
    return found


def _is_dynamic_import(call: ast.Call) -> bool:
    func = call.func
    name = func.id if isinstance(func, ast.Name) else getattr(func, "attr", None)
    return name in ("import_module", "__import__") and bool(call.args)


def imports_of(source: str, dotted: str, is_package: bool, known) -> tuple[set[str], list[str]]:
    """(the ``known`` modules a module imports, its imports the checker cannot follow).

    ``dotted``: the module's name; ``is_package``: it is a package's ``__init__``. A ``from
    package import name`` counts as the submodule ``package.name`` when that is a module, else
    as ``package`` — so ``from prsm_health import X`` is an import of the root.
    """
    tree = ast.parse(source)
    package = dotted if is_package else dotted.rpartition(".")[0]
    found, computed = set(), []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            target = _relative("." * node.level + (node.module or ""), package)
            if target.split(".")[0] != ROOT_NAME:
                continue
            subs = [f"{target}.{a.name}" for a in node.names if f"{target}.{a.name}" in known]
            found.update(subs or [target])
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == ROOT_NAME)
        elif isinstance(node, ast.Call) and _is_dynamic_import(node):
            anchor = node.args[1] if len(node.args) > 1 else None
            for keyword in node.keywords:
                if keyword.arg == "package":
                    anchor = keyword.value
            targets = _dynamic_target(node.args[0], dotted, package, anchor, known)
            if targets is None:
                computed.append(f"line {node.lineno}: {ast.unparse(node)}")
            else:
                found.update(targets)
    maps = _lazy_maps(tree, package)
    if computed and maps:  # the name comes from the module's re-export map: follow the map
        found |= maps
        computed = []
    return {name for name in found if name in known}, computed


def _imports(module: Path) -> tuple[set[str], list[str]]:
    return imports_of(module.read_text(), _dotted(module), module.name == "__init__.py", DOTTED)


def _layer(dotted: str) -> str | None:
    parts = dotted.split(".")
    return parts[1] if len(parts) > 1 else None


def climbs(dotted: str, imported: set[str]) -> set[str]:
    """The imports of module ``dotted`` from a layer above its own, or of the package root."""
    own = LAYERS.index(_layer(dotted))
    return {
        name
        for name in imported
        if _layer(name) is None or LAYERS.index(_layer(name)) > own  # None: the root
    }


def import_graph(imports: dict[str, set[str]]) -> dict[str, set[str]]:
    """Module → the modules it imports, without a package's imports of its own submodules (how
    it re-exports them, not a cycle) — except the root's: it is outside the layers and
    re-exports all of them, so an import of the root from below closes a cycle."""
    return {
        name: {t for t in targets - {name} if name == ROOT_NAME or not t.startswith(name + ".")}
        for name, targets in imports.items()
    }


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import cycles of ``graph`` (Tarjan's strongly connected components of > 1 module)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in graph.get(node, ()):
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
                found.append(sorted(component))

    for name in graph:
        if name not in index:
            visit(name)
    return found


IMPORTS = {name: _imports(path) for name, path in DOTTED.items()}


# ------------------------------------------------------------------------------ the house
def test_layers_are_the_folders():
    folders = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
    loose = sorted(p.name for p in PACKAGE.glob("*.py") if p.name != "__init__.py")
    assert folders == set(LAYERS), (folders ^ set(LAYERS), "a folder that is no layer, or back")
    assert not loose, f"modules outside every layer: {loose}"


@pytest.mark.parametrize("module", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_import_from_a_layer_above_or_the_root(module):
    dotted = _dotted(module)
    bad = climbs(dotted, IMPORTS[dotted][0])
    assert not bad, f"{module.relative_to(PACKAGE)} ({_layer(dotted)}) imports {sorted(bad)}"


@pytest.mark.parametrize("module", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_every_lazy_import_can_be_followed(module):
    rel = str(module.relative_to(PACKAGE))
    computed = IMPORTS[_dotted(module)][1]
    if rel in DYNAMIC:
        assert computed, f"{rel} imports no computed name any more: drop it from DYNAMIC"
    else:
        assert not computed, f"{rel}: the checker cannot follow {computed} (name it in DYNAMIC)"


def test_the_root_re_exports_every_layer_lazily():
    # the root's map is followed, so the cycle test below sees the root's edges
    reached = {_layer(name) for name in IMPORTS[ROOT_NAME][0]}
    assert {"actuator", "simulation", "signals", "diagnostics", "prognostics"} <= reached


def test_no_import_cycle():
    found = cycles(import_graph({name: imported for name, (imported, _) in IMPORTS.items()}))
    assert not found, found


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


TOOLS = sorted((ROOT / "tools").rglob("*.py"))


def _private(dotted: str) -> bool:
    return any(part.startswith("_") and not part.startswith("__") for part in dotted.split("."))


@pytest.mark.parametrize("tool", TOOLS, ids=lambda p: str(p.relative_to(ROOT / "tools")))
def test_tools_use_the_installed_package_s_public_names(tool):
    """A tool imports the package as a user would: no private module or name, no ``sys.path``
    edit (a tool that needs a private name makes it public in the package first)."""
    tree = ast.parse(tool.read_text())
    bad = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == ROOT_NAME:
            bad += [f"{node.module}.{a.name}" for a in node.names if _private(a.name)]
            bad += [node.module] if _private(node.module) else []
        elif isinstance(node, ast.Import):
            bad += [
                a.name for a in node.names if a.name.split(".")[0] == ROOT_NAME and _private(a.name)
            ]
        elif isinstance(node, ast.Attribute) and node.attr == "path":
            if isinstance(node.value, ast.Name) and node.value.id == "sys":
                bad.append(f"sys.path (line {node.lineno})")
    assert not bad, bad


# ------------------------------------------------------------------- the checker checked
#: A lower module (signals, the layer below io) hiding upward imports in every lazy form.
LAZY_CLIMBS = """
import importlib
from importlib import import_module

_EXPORTS = {"replay": "..io.mcap", "Dataset": ("prsm_health.datasets", "Dataset")}


def __getattr__(name):
    module = _EXPORTS[name]
    return getattr(import_module(module if isinstance(module, str) else module[0], __name__),
                   name)


def plot(run):
    return import_module("prsm_health.apps.plots").plot(run)


def serve():
    return importlib.import_module(".diagnostics.diagnosis", package="prsm_health")


def command(name):
    return importlib.import_module(f"prsm_health.apps.cli.{name}")
"""


def test_the_checker_sees_lazy_imports_that_climb():
    dotted = f"{ROOT_NAME}.signals.lazy"
    imported, computed = imports_of(LAZY_CLIMBS, dotted, False, DOTTED)
    assert not computed  # the computed name comes from the map, which is followed
    bad = climbs(dotted, imported)
    assert {
        f"{ROOT_NAME}.io.mcap",  # the map's relative entry
        f"{ROOT_NAME}.datasets",  # the map's (module, attribute) entry
        f"{ROOT_NAME}.apps.plots",  # import_module in a function
        f"{ROOT_NAME}.diagnostics.diagnosis",  # relative, anchored by package=
        f"{ROOT_NAME}.apps.cli.main",  # under an f-string's fixed head
    } <= bad, bad
    # the same calls in the top layer climb nowhere
    assert not climbs(f"{ROOT_NAME}.apps.lazy", imported)


def test_the_checker_names_a_computed_import_it_cannot_follow():
    source = "import importlib\n\ndef load(name):\n    return importlib.import_module(name)\n"
    imported, computed = imports_of(source, f"{ROOT_NAME}.io.loader", False, DOTTED)
    assert not imported and computed == ["line 4: importlib.import_module(name)"]


@pytest.mark.parametrize(
    "statement",
    ["import prsm_health", "from prsm_health import __version__", "from .. import __version__"],
)
def test_the_checker_refuses_an_import_of_the_root(statement):
    dotted = f"{ROOT_NAME}.core.versioned"
    imported, _ = imports_of(f"def f():\n    {statement}\n", dotted, False, DOTTED)
    assert climbs(dotted, imported) == {ROOT_NAME}


def test_a_cycle_through_the_root_is_found():
    root_source = (PACKAGE / "__init__.py").read_text()
    lower = f"{ROOT_NAME}.signals.features"
    known = set(DOTTED)
    imports = {
        ROOT_NAME: imports_of(root_source, ROOT_NAME, True, known)[0],
        lower: imports_of("from prsm_health import __version__\n", lower, False, known)[0],
    }
    assert cycles(import_graph(imports)) == [sorted([ROOT_NAME, lower])]

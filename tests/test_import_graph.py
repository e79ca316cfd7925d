"""The direction of dependencies inside greybox, read from the source with ``ast``.

Every ``import`` statement of every module counts, also those inside
functions and under ``if TYPE_CHECKING:``: an import that only runs later is
still a dependency, and hiding a cycle in a function does not remove it. The
rules (docs/layout.md, "Layer rules"):

- no import cycle between modules;
- only ``greybox.twin`` itself, ``greybox.control``, ``greybox.reproduce`` and
  ``greybox.cli`` import the synthetic twin (the validation studies, ``studies/``
  beside the package, may too: they are not part of it);
- ``greybox.threads`` (thread pools shared by the data readers and the models)
  imports nothing of greybox;
- ``greybox.base`` (the model protocol) and ``greybox.twin.laws.base`` (the
  truth laws' base class) import nothing of greybox, and the twin imports no
  model (``greybox.models``): a truth plant built from the models it tests
  would flatter them;
- the model kinds (``greybox.models``: physical friction, kernel, augmented,
  with their files and machine models) import nothing of the layers above
  them: ``evaluate``, ``predict``, ``discover``, ``reproduce``, ``control``, ``cli``;
- identification (``greybox.identify``: searches, cross-validation, the
  scoring of candidates) imports no model kind: the models stand on it, so the
  choice among the model kinds (``greybox.train.candidates``), which needs
  their registry, sits above them in ``train``;
- training (``greybox.train``, with the choice of a model) sits above the
  models and their files, and below its users, which it imports nothing of: the
  fleet, ``predict``, ``evaluate``, ``live``, ``monitor``, ``process``,
  ``discover``, ``control``, ``reproduce``, ``cli``;
- the fleet's engine (``greybox.fleet`` and ``greybox.fleet.engine``) imports
  no workflow that runs on it (the fleet's runs ``fleet.train``,
  ``fleet.predict``, ``fleet.monitor``, and ``train``, ``predict``,
  ``monitor``, ...);
- prediction (``greybox.predict``) sits above the models, the data and
  ``evaluate`` (metrics, regimes, figures), which import nothing of it, and
  below its users, which it imports nothing of: the fleet, ``live``,
  ``monitor``, ``process``, ``discover``, ``control``, ``reproduce``, ``cli``;
- the monitor (``greybox.monitor``) imports nothing of the fleet, whose
  ``fleet.monitor`` runs it on a cluster;
- the model layer as a whole (:data:`MODEL_LAYER`: the model kinds in
  ``models`` with their registry, their file format and machine models, the
  identification and data layers they stand on) imports nothing outside it:
  no import runs back up the layers (the registry of model kinds imports no
  workflow: the augmented kind of ``greybox discover`` lives in ``models``).

An import names a module (``import greybox.twin.plant``, ``from ..twin import
plant``) or a package's ``__init__`` (``from ..twin import make_dataset``).
Importing a submodule from outside its package also runs the package's
``__init__`` (and its parents'), so that is an edge too: ``identify.initial``
importing ``models.friction.stribeck`` would run ``models/friction/__init__``,
which imports the models, which import ``identify.initial`` — a cycle Python reports only
at run time. From inside a package its own ``__init__`` is not an edge (it is
already running or done).
"""

from __future__ import annotations

import ast
from collections import deque
from pathlib import Path

import pytest

PACKAGE_DIR = Path(__file__).resolve().parents[1] / "greybox"

#: Packages that may import the synthetic twin (besides the twin itself).
TWIN_USERS = ("greybox.control", "greybox.reproduce", "greybox.cli")
#: Layers the models must not depend on.
#: The model kinds and everything they stand on: importing nothing outside this set.
MODEL_LAYER = ("greybox.base", "greybox.errors", "greybox.threads", "greybox.atomic", "greybox.json_values",
               "greybox.provenance", "greybox.metrics", "greybox.data", "greybox.identify", "greybox.models",
               "greybox.models.files")
ABOVE_MODELS = ("greybox.evaluate", "greybox.predict", "greybox.discover", "greybox.reproduce", "greybox.control",
                "greybox.cli")
#: Layers training (``greybox.train``) must not depend on: its users (the fleet, the compensation study, the
#: command line) and the workflows beside it.
ABOVE_TRAIN = ("greybox.fleet", "greybox.predict", "greybox.evaluate", "greybox.live",
               "greybox.monitor", "greybox.process", "greybox.discover", "greybox.control", "greybox.reproduce",
               "greybox.cli")
#: Layers prediction must not depend on (they use it, or stand beside it).
ABOVE_PREDICT = ("greybox.fleet", "greybox.live", "greybox.monitor", "greybox.process", "greybox.discover",
                 "greybox.control", "greybox.reproduce", "greybox.cli")


def _within(module: str, package: str) -> bool:
    """Whether ``module`` is ``package`` or inside it."""
    return module == package or module.startswith(package + ".")


def module_files(package_dir: Path) -> dict[str, Path]:
    """Every module of the package under ``package_dir``: ``{dotted name: file}``."""
    modules = {}
    for path in sorted(package_dir.rglob("*.py")):
        parts = path.relative_to(package_dir.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules[".".join(parts)] = path
    return modules


def _known(name: str, modules) -> str | None:
    """The longest prefix of the dotted ``name`` that is a module of the package, if any."""
    parts = name.split(".")
    for end in range(len(parts), 0, -1):
        candidate = ".".join(parts[:end])
        if candidate in modules:
            return candidate
    return None


def imports_of(module: str, path: Path, modules) -> list[tuple[str, int]]:
    """The package's modules that ``module`` imports anywhere in its source, with the line of each import.

    Parameters
    ----------
    module : str
        Dotted name of the importing module.
    path : Path
        Its source file.
    modules : collection of str
        Dotted names of every module of the package.

    Returns
    -------
    list of (str, int)
        Imported module and line number, in the order of the source.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    own_package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [_known(alias.name, modules) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = own_package[: len(own_package) - (node.level - 1)]
                stem = ".".join(base + (node.module.split(".") if node.module else []))
            else:
                stem = node.module or ""
            # ``from package import name`` imports the submodule ``name`` if there is one, else the package
            targets = [_known(f"{stem}.{alias.name}", modules) or _known(stem, modules) for alias in node.names]
        else:
            continue
        for target in targets:
            if target is None or target == module:
                continue
            found.append((target, node.lineno))
            found += [(package, node.lineno) for package in _parent_packages(target, modules)
                      if not _within(module, package)]
    return sorted(set(found), key=lambda item: (item[1], item[0]))


def _parent_packages(module: str, modules) -> list[str]:
    """The packages of the package that contain ``module`` (the top package excluded: everything is inside it)."""
    parts = module.split(".")
    return [name for name in (".".join(parts[:end]) for end in range(2, len(parts))) if name in modules]


def import_graph(package_dir: Path = PACKAGE_DIR) -> dict[str, dict[str, int]]:
    """``{module: {imported module: first line importing it}}`` over the whole package."""
    modules = module_files(package_dir)
    graph = {}
    for module, path in modules.items():
        edges = {}
        for target, line in imports_of(module, path, modules):
            edges.setdefault(target, line)
        graph[module] = edges
    return graph


def strongly_connected(graph) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index, low, on_stack, stack, components = {}, {}, set(), [], []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    components.append(sorted(component))
    return sorted(components)


def shortest_cycle(graph, component) -> list[str]:
    """A shortest cycle through the first module of ``component``, as a closed list of modules."""
    start, members = component[0], set(component)
    previous = {start: None}
    queue = deque([start])
    while queue:
        node = queue.popleft()
        for child in sorted(graph[node]):
            if child == start:
                path = [node]
                while previous[path[-1]] is not None:
                    path.append(previous[path[-1]])
                return [start, *reversed(path[:-1]), start] if len(path) > 1 else [start, node, start]
            if child in members and child not in previous:
                previous[child] = node
                queue.append(child)
    raise AssertionError(f"no cycle through {start} in its component")  # cannot happen in a component


def cycles(graph) -> list[str]:
    """One line per import cycle: ``a (line) -> b (line) -> ... -> a``, with the line of each import."""
    lines = []
    for component in strongly_connected(graph):
        cycle = shortest_cycle(graph, component)
        steps = [f"{a} (line {graph[a][b]})" for a, b in zip(cycle, cycle[1:])]
        lines.append(" -> ".join(steps + [cycle[-1]]) + f"  (knot of {len(component)}: {', '.join(component)})")
    return lines


def forbidden(graph, importers, imported) -> list[str]:
    """Imports from a module matching ``importers`` of a module matching ``imported`` (predicates)."""
    return [f"{module} (line {line}) imports {target}"
            for module, edges in sorted(graph.items()) if importers(module)
            for target, line in sorted(edges.items()) if imported(target)]


@pytest.fixture(scope="module")
def graph():
    return import_graph()


def test_no_import_cycle(graph):
    found = cycles(graph)
    assert not found, "import cycles (imports inside functions count):\n" + "\n".join(found)


def test_only_the_twin_the_control_loop_reproduce_and_the_cli_import_the_twin(graph):
    found = forbidden(graph,
                      lambda m: not any(_within(m, p) for p in ("greybox.twin", *TWIN_USERS)),
                      lambda t: _within(t, "greybox.twin"))
    assert not found, "the synthetic twin imported outside twin/, control/, reproduce/, cli/:\n" + "\n".join(found)


def test_the_model_protocol_imports_nothing_of_greybox(graph):
    assert "greybox.base" in graph
    found = forbidden(graph, lambda m: m == "greybox.base", lambda t: True)
    assert not found, "greybox/base.py must import nothing of greybox:\n" + "\n".join(found)


def test_the_shared_thread_pools_import_nothing_of_greybox(graph):
    assert "greybox.threads" in graph  # used by the data readers and the models alike: below both
    found = forbidden(graph, lambda m: m == "greybox.threads", lambda t: True)
    assert not found, "greybox/threads.py must import nothing of greybox:\n" + "\n".join(found)


def test_the_truth_laws_base_imports_nothing_of_greybox_and_no_truth_law_uses_a_model(graph):
    assert "greybox.twin.laws.base" in graph
    found = forbidden(graph, lambda m: m == "greybox.twin.laws.base", lambda t: True)
    assert not found, "greybox/twin/laws/base.py must import nothing of greybox:\n" + "\n".join(found)
    found = forbidden(graph, lambda m: _within(m, "greybox.twin"),
                      lambda t: _within(t, "greybox.models"))
    assert not found, "the truth plants must not be built from the models they test:\n" + "\n".join(found)


def test_the_models_import_nothing_of_the_layers_above_them(graph):
    found = forbidden(graph,
                      lambda m: _within(m, "greybox.models"),
                      lambda t: any(_within(t, p) for p in ABOVE_MODELS))
    assert not found, "models/ depends on a layer above it:\n" + "\n".join(found)


def test_identification_imports_no_model_kind(graph):
    assert "greybox.identify.selection" in graph  # the scoring of candidates by held-out runs
    found = forbidden(graph, lambda m: _within(m, "greybox.identify"), lambda t: _within(t, "greybox.models"))
    assert not found, "greybox/identify/ imports the models that stand on it:\n" + "\n".join(found)


def test_the_fleet_engine_imports_no_workflow(graph):
    assert "greybox.fleet.engine" in graph  # every fleet run's engine: predict and monitor import it
    runs = ("greybox.fleet.train", "greybox.fleet.predict", "greybox.fleet.monitor")
    assert all(run in graph for run in runs)
    found = forbidden(graph, lambda m: m in ("greybox.fleet", "greybox.fleet.engine"),
                      lambda t: any(_within(t, p) for p in (*runs, "greybox.train", *ABOVE_TRAIN[1:])))
    assert not found, "the fleet engine depends on a workflow that runs on it:\n" + "\n".join(found)


def test_the_workflows_the_fleet_runs_import_nothing_of_it(graph):
    found = forbidden(graph, lambda m: any(_within(m, p) for p in ("greybox.train", "greybox.predict",
                                                                   "greybox.monitor")),
                      lambda t: _within(t, "greybox.fleet"))
    assert not found, "a workflow imports the fleet that runs it (the command line picks the fleet run):\n" + \
        "\n".join(found)


def test_training_imports_nothing_of_its_users(graph):
    assert "greybox.train.logs" in graph  # the one entry point of training
    found = forbidden(graph, lambda m: _within(m, "greybox.train"),
                      lambda t: any(_within(t, p) for p in ABOVE_TRAIN))
    assert not found, "greybox/train/ depends on a layer above it:\n" + "\n".join(found)


def test_prediction_imports_nothing_of_its_users_and_evaluate_nothing_of_prediction(graph):
    assert "greybox.predict.run" in graph  # the one entry point of prediction
    found = forbidden(graph, lambda m: _within(m, "greybox.predict"),
                      lambda t: any(_within(t, p) for p in ABOVE_PREDICT))
    assert not found, "greybox/predict/ depends on a layer above it:\n" + "\n".join(found)
    found = forbidden(graph, lambda m: _within(m, "greybox.evaluate"), lambda t: _within(t, "greybox.predict"))
    assert not found, "greybox/evaluate/ (metrics, reports, figures) depends on prediction:\n" + "\n".join(found)


def test_the_model_layer_imports_nothing_above_it(graph):
    assert "greybox.models.registry" in graph and "greybox.models.augmented" in graph
    found = forbidden(graph,
                      lambda m: any(_within(m, p) for p in MODEL_LAYER),
                      lambda t: t != "greybox" and not any(_within(t, p) for p in MODEL_LAYER))
    assert not found, "an import runs back up the layers (the model layer imports a workflow):\n" + "\n".join(found)


# ---------------------------------------------------------------- the checker itself
def _package(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root / "pkg"


def test_the_walker_sees_imports_inside_functions_and_relative_ones(tmp_path):
    package = _package(tmp_path, {
        "pkg/__init__.py": "",
        "pkg/a.py": "from .b import f\n",
        "pkg/b.py": "def f():\n    from . import c\n",
        "pkg/c.py": "def g():\n    import pkg.a\n",
        "pkg/sub/__init__.py": "from .d import x\n",
        "pkg/sub/d.py": "from ..a import f\nx = 1\n",
        "pkg/e.py": "from pkg import sub\nfrom pkg.sub import x\n",
    })
    found = import_graph(package)
    assert found["pkg.a"] == {"pkg.b": 1}
    assert found["pkg.b"] == {"pkg.c": 2}
    assert found["pkg.c"] == {"pkg.a": 2}
    assert found["pkg.sub"] == {"pkg.sub.d": 1}
    assert found["pkg.sub.d"] == {"pkg.a": 1}
    assert found["pkg.e"] == {"pkg.sub": 1}
    (line,) = cycles(found)
    assert line.startswith("pkg.a (line 1) -> pkg.b (line 2) -> pkg.c (line 2) -> pkg.a")
    assert forbidden(found, lambda m: m == "pkg.sub.d", lambda t: _within(t, "pkg")) == [
        "pkg.sub.d (line 1) imports pkg.a"]


def test_a_package_importing_its_own_modules_is_no_cycle(tmp_path):
    package = _package(tmp_path, {
        "pkg/__init__.py": "from .a import f\nfrom .b import g\n",
        "pkg/a.py": "def f():\n    return 1\n",
        "pkg/b.py": "from .a import f\n\ndef g():\n    return f()\n",
    })
    assert cycles(import_graph(package)) == []


def test_a_submodule_import_from_outside_runs_its_package_init(tmp_path):
    """``b.x`` importing ``a.leaf`` runs ``a/__init__``, which imports ``a.model``, which imports ``b.x``."""
    root = tmp_path / "pkg"
    for folder in (root, root / "a", root / "b"):
        folder.mkdir()
        (folder / "__init__.py").write_text("")
    (root / "a" / "__init__.py").write_text("from .model import Model\n")
    (root / "a" / "model.py").write_text("from ..b.x import helper\n")
    (root / "a" / "leaf.py").write_text("")
    (root / "b" / "x.py").write_text("from ..a.leaf import *\n")
    assert any("pkg.a" in line and "pkg.b.x" in line for line in cycles(import_graph(root)))


def test_the_package_imports_nothing_of_the_repository_folders():
    """``studies/``, ``tests/``, ``scripts/`` and ``benchmarks/`` sit beside the package and are not installed."""
    outside = ("studies", "tests", "scripts", "benchmarks", "conftest", "friction_reference", "friction_signals")
    found = []
    for module, path in module_files(PACKAGE_DIR).items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([alias.name for alias in node.names] if isinstance(node, ast.Import)
                     else [node.module] if isinstance(node, ast.ImportFrom) and not node.level else [])
            found += [f"{module} (line {node.lineno}) imports {name}" for name in names
                      if name and name.split(".")[0] in outside]
    assert not found, "the installed package imports a folder that is not installed:\n" + "\n".join(found)

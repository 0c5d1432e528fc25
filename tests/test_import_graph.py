"""Data flows one way through the package: no import cycle between its top-level subpackages and modules.

Every import of every module counts, function-level ones included (a lazy import is still a dependency). The
package root (``collision_reflex/__init__.py``) is not a node: it re-exports everything, and Python imports a
parent package before any of its modules whatever the module imports.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "collision_reflex"


def _unit(module: str) -> str | None:
    """The top-level node of a dotted module name inside the package (``optimize`` for
    ``collision_reflex.optimize.pareto``), or None outside it or for the root."""
    parts = module.split(".")
    if parts[0] != "collision_reflex" or len(parts) == 1:
        return None
    return parts[1]


def _module_name(package: Path, path: Path) -> tuple[str, bool]:
    """The dotted name of a source file and whether it is a package's ``__init__``."""
    relative = path.relative_to(package.parent).with_suffix("")
    parts = list(relative.parts)
    is_package = parts[-1] == "__init__"
    if is_package:
        parts = parts[:-1]
    return ".".join(parts), is_package


def _imports(package: Path, path: Path) -> set[str]:
    """Every module a file imports (absolute dotted names; ``from . import x`` counts ``x`` as a module)."""
    name, is_package = _module_name(package, path)
    here = name.split(".") if is_package else name.split(".")[:-1]
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = here[: len(here) - node.level + 1] if node.level else []
            target = ".".join([*base, *(node.module.split(".") if node.module else [])])
            out.add(target)
            out.update(f"{target}.{alias.name}" for alias in node.names)
    return out


def import_graph(package: Path) -> dict[str, set[str]]:
    """Edges between the package's top-level nodes: ``graph[a]`` holds every node some module of ``a`` imports."""
    graph: dict[str, set[str]] = {}
    for path in sorted(package.rglob("*.py")):
        source = _unit(_module_name(package, path)[0])
        if source is None:
            continue
        targets = {_unit(module) for module in _imports(package, path)}
        graph.setdefault(source, set()).update(t for t in targets if t is not None and t != source)
    # ``from .optimize import pareto`` also names the attribute: keep only names that are nodes.
    return {source: {t for t in targets if t in graph} for source, targets in graph.items()}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle of the graph as a path ``[a, b, ..., a]``, or None (depth-first search)."""
    state: dict[str, int] = {}  # 1: on the current path, 2: finished
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for target in sorted(graph.get(node, ())):
            if state.get(target) == 1:
                return [*path[path.index(target) :], target]
            if target not in state and (cycle := visit(target)) is not None:
                return cycle
        state[node] = 2
        path.pop()
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)) is not None:
            return cycle
    return None


def write_package(folder: Path, files: dict[str, str]) -> Path:
    """A package ``collision_reflex`` in ``folder`` made of ``files`` (path inside the package: source)."""
    package = folder / "collision_reflex"
    for name, text in files.items():
        (package / name).parent.mkdir(parents=True, exist_ok=True)
        (package / name).write_text(text)
    return package


def test_no_import_cycle_between_subpackages():
    graph = import_graph(PACKAGE)
    assert {"model", "optimize", "study", "report", "plots", "errors"} <= set(graph)
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_the_cycle_finder_finds_the_cycles_it_must(tmp_path):
    # The two cycles the package had: study <-> report (through the run folder) and optimize <-> plots (the front
    # plot), written as lazy, function-level imports and relative imports of both kinds.
    files = {
        "__init__.py": "from .optimize import pareto\n",
        "optimize/__init__.py": "",
        "optimize/pareto.py": "def plot():\n    from ..plots.pareto import plot_pareto\n",
        "plots/__init__.py": "",
        "plots/pareto.py": "from ..optimize import problem\n",
        "study/__init__.py": "",
        "study/runner.py": "def run():\n    from ..report import write_outputs\n",
        "report/__init__.py": "from .outputs import write_outputs\n",
        "report/outputs.py": "from ..study.store import DESIGNS\nimport collision_reflex.errors\n",
        "errors.py": "",
    }
    package = write_package(tmp_path, files)
    graph = import_graph(package)
    assert graph["optimize"] == {"plots"} and graph["plots"] == {"optimize"}
    assert graph["report"] == {"study", "errors"}
    assert find_cycle(graph) == ["optimize", "plots", "optimize"]
    (package / "plots/pareto.py").write_text("")
    assert find_cycle(graph := import_graph(package)) == ["report", "study", "report"], graph
    (package / "study/runner.py").write_text("")
    assert find_cycle(import_graph(package)) is None


@pytest.mark.parametrize(
    ("module", "node"), [("collision_reflex.optimize.pareto", "optimize"), ("collision_reflex", None)]
)
def test_nodes_are_top_level_names(module, node):
    assert _unit(module) == node


def test_the_root_holds_the_workflow_each_name_from_the_subpackage_that_exports_it():
    import importlib

    import collision_reflex as cr

    assert len(cr.__all__) <= 25 and len(set(cr.__all__)) == len(cr.__all__)
    for package, names in cr._WORKFLOW.items():
        module = importlib.import_module(package, "collision_reflex")
        for name in names:
            assert getattr(cr, name) is getattr(module, name), name
            assert name in getattr(module, "__all__", dir(module)), f"{name} is not public in {package}"
    # The common workflow is there; everything else is one subpackage away.
    assert {"load_study", "run_study", "build_problem", "solve", "pareto_front", "snap_to_catalogue"} <= set(
        cr.__all__
    )
    assert {"export_design", "render_report", "Arm", "Actuator", "InvalidParameter"} <= set(cr.__all__)
    assert cr.arm.effective_mass is importlib.import_module("collision_reflex.arm.metrics").effective_mass
    assert cr.vocabulary.SENSING_SCHEMES == ("force", "position", "current")

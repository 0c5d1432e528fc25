"""The source stays in small rooms a newcomer can carry: short modules and functions, imports that run one way.

- no module over 600 lines, no function over 100;
- no import loop between files (function-level imports count: a lazy import is still a dependency);
- a function imports the package's own modules only to defer a heavy library, and says so with a ``# lazy:``
  comment on the import (or the line above it).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from test_import_graph import PACKAGE, find_cycle, write_package

MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 100


def _sources(package: Path = PACKAGE) -> list[Path]:
    return sorted(package.rglob("*.py"))


def _module_name(package: Path, path: Path) -> str:
    parts = list(path.relative_to(package.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def _type_checking_nodes(tree: ast.Module) -> set[int]:
    """The ids of the import nodes under ``if TYPE_CHECKING:`` (not run, so not a dependency)."""
    hidden: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            hidden.update(id(child) for statement in node.body for child in ast.walk(statement))
    return hidden


def file_import_graph(package: Path = PACKAGE) -> dict[str, set[str]]:
    """Edges between the package's files: ``graph[a]`` holds every file of the package that ``a`` imports.

    ``from .pkg import name`` is an edge to the module ``pkg.name`` when there is one, else to ``pkg`` (its
    ``__init__``, which Python runs first). The package root is not a node: it binds names lazily.
    """
    paths = {_module_name(package, path): path for path in _sources(package)}
    root = package.name
    graph: dict[str, set[str]] = {}
    for name, path in paths.items():
        if name == root:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        hidden = _type_checking_nodes(tree)
        here = name.split(".") if _is_package(path) else name.split(".")[:-1]
        targets: set[str] = set()
        for node in ast.walk(tree):
            if id(node) in hidden:
                continue
            if isinstance(node, ast.Import):
                targets.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = here[: len(here) - node.level + 1] if node.level else []
                module = ".".join([*base, *(node.module.split(".") if node.module else [])])
                for alias in node.names:
                    targets.add(f"{module}.{alias.name}" if f"{module}.{alias.name}" in paths else module)
        graph[name] = {t for t in targets if t in paths and t not in (root, name)}
    return graph


def test_no_module_is_over_600_lines():
    long = {
        str(path.relative_to(PACKAGE)): n
        for path in _sources()
        if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES
    }
    assert not long, f"modules over {MAX_MODULE_LINES} lines: {long}"


def test_no_function_is_over_100_lines():
    long = {}
    for path in _sources():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                if (n := node.end_lineno - node.lineno + 1) > MAX_FUNCTION_LINES:
                    long[f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name}"] = n
    assert not long, f"functions over {MAX_FUNCTION_LINES} lines: {long}"


def test_no_import_loop_between_files():
    graph = file_import_graph()
    assert {"collision_reflex.optimize.solve", "collision_reflex.study.runner"} <= set(graph)
    cycle = find_cycle(graph)
    assert cycle is None, "import loop: " + " -> ".join(cycle or [])


def _says_lazy(lines: list[str], node: ast.stmt) -> bool:
    """Whether ``# lazy:`` stands on the import, or above the block of imports (and comments) it belongs to."""
    if any("# lazy:" in line for line in lines[node.lineno - 1 : node.end_lineno]):
        return True
    above = node.lineno - 2
    while above >= 0 and lines[above].strip().startswith(("from ", "import ", "#", ")")):
        if "# lazy:" in lines[above]:
            return True
        above -= 1
    return False


def test_a_function_imports_its_own_package_only_to_defer_a_heavy_library():
    unexplained = []
    for path in _sources():
        lines = path.read_text(encoding="utf-8").splitlines()
        for function in ast.walk(ast.parse("\n".join(lines))):
            if not isinstance(function, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            for node in ast.walk(function):
                own = (
                    isinstance(node, ast.ImportFrom)
                    and (node.level > 0 or (node.module or "").startswith("collision_reflex"))
                ) or (
                    isinstance(node, ast.Import)
                    and any(a.name.startswith("collision_reflex") for a in node.names)
                )
                if own and not _says_lazy(lines, node):
                    unexplained.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert not unexplained, f"function-level imports of the package without a '# lazy:' reason: {unexplained}"


@pytest.fixture
def loop_package(tmp_path: Path) -> Path:
    files = {
        "__init__.py": "from .optimize import solve\n",
        "optimize/__init__.py": "from .solve import solve\n",
        "optimize/solve.py": "from .feasibility import feasible\ndef solve():\n    pass\n",
        "optimize/feasibility.py": "def feasible():\n    from .solve import solve  # hidden loop\n",
        "optimize/types.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .solve import solve\n",
    }
    return write_package(tmp_path, files)


def test_the_file_graph_sees_a_loop_kept_open_by_a_function_level_import(loop_package):
    graph = file_import_graph(loop_package)
    assert graph["collision_reflex.optimize.types"] == set()  # TYPE_CHECKING imports do not run
    assert graph["collision_reflex.optimize"] == {"collision_reflex.optimize.solve"}
    cycle = find_cycle(graph)
    assert cycle is not None and set(cycle) == {
        "collision_reflex.optimize.solve",
        "collision_reflex.optimize.feasibility",
    }
    (loop_package / "optimize/feasibility.py").write_text("def feasible():\n    pass\n")
    assert find_cycle(file_import_graph(loop_package)) is None


def _vocabularies() -> dict[str, tuple[str, ...]]:
    """Every vocabulary: the same names in another order are another list (an argument order, say)."""
    from collision_reflex import vocabulary

    return {
        name: value
        for name, value in vars(vocabulary).items()
        if name.isupper() and isinstance(value, tuple) and all(isinstance(v, str) for v in value)
    }


def _string_sets(tree: ast.AST) -> list[tuple[int, tuple[str, ...]]]:
    """Every literal tuple, list, set or ``Literal[...]`` of two or more strings, with its line."""
    found = []
    for node in ast.walk(tree):
        elements = None
        if isinstance(node, ast.Tuple | ast.List | ast.Set):
            elements = node.elts
        elif isinstance(node, ast.Subscript) and ast.unparse(node.value).endswith("Literal"):
            elements = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
        if elements and len(elements) >= 2:
            if all(isinstance(e, ast.Constant) and isinstance(e.value, str) for e in elements):
                found.append((node.lineno, tuple(e.value for e in elements)))
    return found


def test_each_vocabulary_is_written_once():
    vocabularies = _vocabularies()
    assert {"SENSING_SCHEMES", "OBJECTIVE_NAMES", "GEARBOX_KINDS", "SCALING_LAW_NAMES", "EXECUTORS"} <= set(
        vocabularies
    )
    copies = []
    for path in _sources():
        if path.name == "vocabulary.py":
            continue
        for line, values in _string_sets(ast.parse(path.read_text(encoding="utf-8"))):
            copies += [
                f"{path.relative_to(PACKAGE)}:{line} {name}"
                for name, v in vocabularies.items()
                if v == values
            ]
    assert not copies, f"vocabularies written again outside collision_reflex/vocabulary.py: {copies}"


def test_the_tables_keyed_by_a_vocabulary_cover_it_exactly():
    from collision_reflex.hardware.gearbox_scaling import GEARBOX_SCALING
    from collision_reflex.hardware.motors import SCALING_LAWS
    from collision_reflex.optimize.objectives import OBJECTIVES
    from collision_reflex.vocabulary import GEARBOX_KINDS, OBJECTIVE_NAMES, SCALING_LAW_NAMES

    assert set(GEARBOX_SCALING) == set(GEARBOX_KINDS)
    assert set(SCALING_LAWS) == set(SCALING_LAW_NAMES)
    assert tuple(OBJECTIVES) == OBJECTIVE_NAMES


def test_the_vocabulary_check_finds_a_copy():
    tree = ast.parse('KINDS = ("force", "position", "current")\nx: Literal["serial", "processes", "dask"]\n')
    vocabularies = _vocabularies()
    sets = [values for _, values in _string_sets(tree)]
    assert vocabularies["SENSING_SCHEMES"] in sets and vocabularies["EXECUTORS"] in sets


def test_no_set_of_names_is_defined_in_two_modules():
    # A module-level tuple, list or set of two or more strings written in two modules is a vocabulary: it
    # belongs in collision_reflex/vocabulary.py, once.
    where: dict[frozenset[str], list[str]] = {}  # the same names in any order
    for path in _sources():
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.Assign | ast.AnnAssign) and node.value is not None:
                for line, values in _string_sets(node.value):
                    where.setdefault(frozenset(values), []).append(f"{path.relative_to(PACKAGE)}:{line}")
    twice = {
        ", ".join(sorted(v)): places
        for v, places in where.items()
        if len({p.split(":")[0] for p in places}) > 1
    }
    assert not twice, f"sets of names defined in more than one module: {twice}"

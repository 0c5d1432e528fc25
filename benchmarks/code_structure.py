"""The source's structure: module and function sizes, function-level imports of the package, the root's names.

The limits themselves are tests (``tests/test_structure.py``); this prints where the source stands against them,
for the record. Run: ``PYTHONPATH=src python benchmarks/code_structure.py``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import collision_reflex as cr

PACKAGE = Path(cr.__file__).resolve().parent  # the tree imported (PYTHONPATH), not this script's


def _own_import(node: ast.AST) -> bool:
    if isinstance(node, ast.ImportFrom):
        return node.level > 0 or (node.module or "").startswith("collision_reflex")
    return isinstance(node, ast.Import) and any(a.name.startswith("collision_reflex") for a in node.names)


def main() -> None:
    modules: list[tuple[int, str]] = []
    functions: list[tuple[int, str]] = []
    lazy = 0
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        name = str(path.relative_to(PACKAGE))
        modules.append((len(text.splitlines()), name))
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                functions.append((node.end_lineno - node.lineno + 1, f"{name}:{node.lineno} {node.name}"))
                lazy += sum(_own_import(inner) for inner in ast.walk(node))
    modules.sort(reverse=True)
    functions.sort(reverse=True)
    print(f"modules: {len(modules)}, {sum(n for n, _ in modules)} lines")
    print("largest modules: " + ", ".join(f"{name} {n}" for n, name in modules[:3]))
    print("longest functions: " + ", ".join(f"{name} {n}" for n, name in functions[:3]))
    print(f"function-level imports of the package: {lazy}")
    print(f"names at the package root: {len(cr.__all__)} (__version__ among them)")


if __name__ == "__main__":
    main()

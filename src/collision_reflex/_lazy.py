"""Public names imported on first access (PEP 562): importing a package loads only the modules a caller uses."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any


def lazy_attributes(
    namespace: dict[str, Any], where: dict[str, tuple[str, str]], public: list[str]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """A package's ``__getattr__`` and ``__dir__``.

    ``namespace`` is the package's ``globals()``; ``where`` maps each public name to its module (relative to
    the package) and attribute there; ``public`` is the package's ``__all__``. Any other identifier is tried
    as a subpackage (bound as an attribute only once something imports it).
    """
    package = namespace["__name__"]

    def __getattr__(name: str) -> object:
        """Import the public name ``name`` (or the subpackage ``name``) on first access."""
        if name in where:
            module, attribute = where[name]
            value = getattr(importlib.import_module(module, package), attribute)
        elif name.startswith("__") or not name.isidentifier():
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        else:
            try:
                value = importlib.import_module(f".{name}", package)
            except ModuleNotFoundError as missing:
                if missing.name != f"{package}.{name}":
                    raise
                raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        namespace[name] = value  # later accesses find it without calling __getattr__
        return value

    def __dir__() -> list[str]:
        """The package's attributes and every public name, imported or not."""
        return sorted(set(namespace) | set(public))

    return __getattr__, __dir__

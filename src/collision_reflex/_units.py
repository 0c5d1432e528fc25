"""The one pint unit registry of the package.

Building a registry takes a while, and quantities from two registries cannot be combined.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pint


@functools.cache
def unit_registry() -> pint.UnitRegistry:
    """The registry every unit string of the package is read with: study files, catalogues, traces."""
    import pint

    try:
        # pint keeps its parsed unit definitions in the user's cache folder: about 0.1 s less at every start
        # (``crx validate``) than parsing its definition file again.
        return pint.UnitRegistry(cache_folder=":auto:")
    except Exception:  # an unwritable folder, or a cache file another process is still writing: parse it
        return pint.UnitRegistry()

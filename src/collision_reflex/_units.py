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

    # Not pint's on-disk cache (0.1 s faster): the package writes nothing outside the folders it is given.
    return pint.UnitRegistry()

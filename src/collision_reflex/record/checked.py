"""How a saved run record is checked against its type, and the errors of a damaged or missing one.

Every record type is a ``typing_extensions`` TypedDict (pydantic validates the standard library's only from
Python 3.12) decorated with :func:`checked`: no key missing or unknown, no conversion, every number finite.
"""

from __future__ import annotations

from typing import Annotated, TypeVar

from annotated_types import Ge, Gt, Le

from ..errors import CollisionReflexError

Positive = Annotated[float, Gt(0)]
"""A physical quantity that is above zero in every record a run writes (a mass of a motor, a gear ratio)."""
NonNegative = Annotated[float, Ge(0)]
"""A physical quantity a run writes as zero or more (a gearbox's mass, a required torque)."""
Efficiency = Annotated[float, Gt(0), Le(1)]
"""A gearbox efficiency, in (0, 1]."""

STRICT = {"extra": "forbid", "strict": True, "allow_inf_nan": False}
"""How a saved record is checked: no unknown key, no conversion (a number is a number, not text), finite numbers."""
_Kind = TypeVar("_Kind")


def checked(kind: _Kind) -> _Kind:
    """Give a record type :data:`STRICT` as its pydantic configuration (the key pydantic reads on a TypedDict)."""
    setattr(kind, "__pydantic_config__", STRICT)  # noqa: B010 (a TypedDict declares no such attribute)
    return kind


class ResultsMissing(CollisionReflexError, FileNotFoundError):
    """A folder has no saved results to report on."""


class ResultsDamaged(CollisionReflexError, ValueError):
    """A field of the saved results is missing or not what the run writes; the message names the field."""

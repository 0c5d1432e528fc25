"""What every section of a study file is built on: the base model and the field types the sections share."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

PositiveInt = Annotated[int, Field(ge=1, strict=True)]
Name = Annotated[str, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9._-]*$", max_length=80)]


class Spec(BaseModel):
    """A section of a study file: unknown keys refused, frozen, defaults validated."""

    # defer_build: a model's validator is built on its first use, not at import (a cost every start would pay).
    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True, defer_build=True)


def exactly_one(model: BaseModel, names: tuple[str, ...], what: str) -> None:
    """Refuse ``model`` unless exactly one of its fields ``names`` is given (``what`` names them in the message)."""
    given = [name for name in names if getattr(model, name) is not None]
    if len(given) != 1:
        found = "none of them" if not given else " and ".join(given)
        raise ValueError(f"exactly one of {', '.join(names)} for {what} (found {found})")

"""Deprecated keyword spellings, handled by one decorator.

An old name keeps working, with a warning that names the new one.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])


def renamed_keywords(**old_to_new: str) -> Callable[[F], F]:
    """Accept ``old=value`` for each ``old="new"`` pair, warn (``DeprecationWarning``) and pass it as ``new``.

    Giving both spellings is an error (``TypeError``, as Python gives for a duplicated argument).
    """

    def decorate(function: F) -> F:
        @functools.wraps(function)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            for old, new in old_to_new.items():
                if old in kwargs:
                    if new in kwargs:
                        raise TypeError(
                            f"{function.__qualname__}() got both {old!r} and {new!r}; give {new!r}"
                        )
                    warnings.warn(
                        f"{function.__qualname__}(): the keyword {old!r} is deprecated; call it {new!r}",
                        DeprecationWarning,
                        stacklevel=2,
                    )
                    kwargs[new] = kwargs.pop(old)
            return function(*args, **kwargs)

        return wrapper  # type: ignore[return-value]

    return decorate

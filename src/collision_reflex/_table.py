"""Text tables with units in their column headers (``time [s]``, ``shoulder [deg]``).

The one CSV reader of force-time traces and joint trajectories.
"""

from __future__ import annotations

import io
import re
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

HEADER = re.compile(r"^\s*(?P<name>[^\[\(]*?)\s*(?:[\[\(]\s*(?P<unit>[^\]\)]*?)\s*[\]\)])?\s*$")
"""A column header: a name and an optional unit in brackets or parentheses."""


class TableProblem(Exception):
    """The text is not a table; ``line`` is the 1-based line of the problem. Callers turn it into their error."""

    def __init__(self, reason: str, line: int) -> None:
        super().__init__(reason)
        self.reason = reason
        self.line = line


def header_index(lines: list[str]) -> int | None:
    """The 0-based index of the header: the first line that is neither blank nor a ``#`` comment (None: none)."""
    for index, line in enumerate(lines):
        if line.strip() and not line.startswith("#"):
            return index
    return None


def read_table(lines: list[str], header_line: int) -> pd.DataFrame:
    """The CSV table from ``lines[header_line]`` (0-based: the header) on, every cell as text.

    Trailing blank lines end the table; blank lines inside the data are kept (they are reported as missing
    values by the caller's checks).
    """
    import pandas as pd

    try:
        table = pd.read_csv(
            io.StringIO("\n".join(lines[header_line:])),
            skip_blank_lines=False,
            dtype=str,
            keep_default_na=False,
            skipinitialspace=True,
        )
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as error:
        # pandas' message spans lines and counts from the header: one line, located by file line.
        reason = " ".join(str(error).split())
        raise TableProblem(f"not a CSV table ({reason})", _file_line(reason, header_line)) from None
    blank = (table == "").all(axis=1).to_numpy()
    last = len(blank) - int(np.argmin(blank[::-1])) if not blank.all() else 0
    return table.iloc[:last]


def _file_line(reason: str, header_line: int) -> int:
    """The 1-based file line a pandas parser message points at (the header's if it names none).

    pandas counts "line N" from 1 at the header, and "row N" from 0 at the header.
    """
    match = re.search(r"\b(line|row) (\d+)", reason)
    if match is None:
        return header_line + 1
    number = int(match[2])
    return header_line + number + (1 if match[1] == "row" else 0)

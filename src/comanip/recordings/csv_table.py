"""Reading a CSV table by column name, with one-line errors that name the file, the column and the row."""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path

import numpy as np


def read_table(path: str | Path, what: str, required: Sequence[str], numeric: Sequence[str]) -> dict[str, np.ndarray]:
    """The columns of a CSV file with a header row, keyed by column name.

    Args:
        path: the CSV file.
        what: what the file holds, for messages (e.g. "recordings").
        required: columns that must be present.
        numeric: columns (when present) converted to finite floats; the others stay strings.

    Returns:
        {column: array (rows,)}, float for the numeric columns, str (stripped) for the others.

    Raises:
        ValueError (one line) when the path is not a file, the file is empty, a required column is missing,
        or a numeric value is not a finite number.
    """
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{what} {str(path)!r} is a directory; give a CSV file")
    if not path.is_file():
        raise ValueError(f"{what} file {str(path)!r} does not exist")
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = [name.strip() for name in next(reader, [])]
        rows = [row for row in reader if any(cell.strip() for cell in row)]
    if not header:
        raise ValueError(f"{what} file {str(path)!r} is empty; it needs a header row with the columns {list(required)}")
    missing = [name for name in required if name not in header]
    if missing:
        raise ValueError(f"{what} file {str(path)!r} lacks the columns {missing}; its header is {header}")
    if not rows:
        raise ValueError(f"{what} file {str(path)!r} has a header but no rows")
    short = [k for k, row in enumerate(rows) if len(row) != len(header)]
    if short:
        raise ValueError(f"{what} file {str(path)!r}: data row {short[0] + 1} has {len(rows[short[0]])} values, the header {len(header)}")
    table = {name: np.array([row[k].strip() for row in rows]) for k, name in enumerate(header)}
    for name in (c for c in numeric if c in table):
        table[name] = _finite_column(path, what, name, table[name])
    return table


def _finite_column(path: Path, what: str, name: str, cells: np.ndarray) -> np.ndarray:
    values = np.empty(len(cells))
    for k, cell in enumerate(cells):
        try:
            values[k] = float(cell)
        except ValueError:
            raise ValueError(f"{what} file {str(path)!r}: column {name!r}, data row {k + 1} is {str(cell)!r}, not a number") from None
        if not np.isfinite(values[k]):
            raise ValueError(f"{what} file {str(path)!r}: column {name!r}, data row {k + 1} is {str(cell)!r}; values must be finite numbers")
    return values

"""Tables in, tables out: file paths, dicts of arrays and pandas DataFrames as inputs of the
CLI's readers, and results as pandas DataFrames when pandas is installed.

A dict or DataFrame is written as CSV text (every float in shortest round-trip form, so the
reader sees exactly the same doubles) and read by the same Rust reader as a file on the command
line: the same validation, the same messages. Errors in such a table name its row instead of a
line of a file.
"""

from __future__ import annotations

import csv
import io
import math
import numbers
import os
from collections.abc import Mapping
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from ._restitution import InputError

TableLike = Union[str, "os.PathLike[str]", Mapping, Any]


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, (bool, np.bool_)):
        return str(bool(v))
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        x = float(v)
        # repr of a float is its shortest round-trip form; a missing value (NaN) is an empty
        # cell, which the reader reports as missing where a number is required.
        return "" if math.isnan(x) else repr(x)
    s = str(v)
    if "\n" in s or "\r" in s:
        raise InputError(f"cell {s!r}: line breaks are not allowed in a table cell")
    return s


class Source:
    """Where a table comes from: keyword arguments for the extension, and row labels."""

    def __init__(self, data: TableLike, columns: Optional[Sequence[str]] = None):
        self.labels: Optional[List[Any]] = None
        if isinstance(data, (str, os.PathLike)):
            self.kwargs: Dict[str, Any] = {"path": os.fspath(data)}
            return
        name, table = _columns_of(data)
        if columns is not None:
            table = {k: v for k, v in table.items() if k in columns}
        lengths = {k: len(v) for k, v in table.items()}
        if len(set(lengths.values())) > 1:
            raise InputError(f"{name}: columns of different lengths: {lengths}")
        n = next(iter(lengths.values()), 0)
        if self.labels is None:
            self.labels = list(range(n))
        if hasattr(data, "index"):
            self.labels = list(data.index)
        buf = io.StringIO()
        # Every field quoted: a cell such as '#1' must not read as a comment line.
        w = csv.writer(buf, quoting=csv.QUOTE_ALL, lineterminator="\n")
        w.writerow(list(table))
        cols = list(table.values())
        for i in range(n):
            w.writerow([_cell(c[i]) for c in cols])
        self.kwargs = {"name": name, "text": buf.getvalue()}

    def relocate(self, err: BaseException) -> BaseException:
        """An error about line L of the CSV text, reworded to name row L - 2 of the table; one
        about the header line (L = 1) names no row (it is about the table's columns), and the
        reader's words for a file's header become the table's."""
        line = getattr(err, "line", None)
        if self.labels is None or not isinstance(err, InputError):
            return err
        detail = str(getattr(err, "detail", err))
        if line is None:
            if detail != _NO_HEADER:
                return err
            detail, label = "the table has no columns", None
        else:
            row = line - 2
            label = self.labels[row] if 0 <= row < len(self.labels) else None
        where = f"{getattr(err, 'path', '')}"
        if label is not None:
            where += f": row {label!r}"
        col = getattr(err, "column", None)
        if col is not None:
            where += f": column '{col}'"
        for file_words, table_words in _HEADER_WORDS:
            detail = detail.replace(file_words, table_words)
        new = InputError(f"{where}: {detail}")
        for a in ("path", "column", "kind"):
            setattr(new, a, getattr(err, a, None))
        new.detail = detail
        new.line = line
        new.row = label
        return new


    def relocate_lines(self, messages: List[str]) -> List[str]:
        """Messages that start 'NAME:LINE: ', reworded to name the table's row."""
        if self.labels is None:
            return list(messages)
        name = self.kwargs["name"]
        out = []
        for m in messages:
            head, sep, rest = m[len(name) + 1 :].partition(": ")
            if m.startswith(name + ":") and sep and head.isdigit():
                row = int(head) - 2
                if 0 <= row < len(self.labels):
                    m = f"{name}: row {self.labels[row]!r}: {rest}"
                else:
                    m = f"{name}: {rest}"
            out.append(m)
        return out


# The CSV reader's words for a file's header line, as a table's (the CSV text of a table is its
# columns' names, then its rows).
_NO_HEADER = "no header line (the file is empty)"
_HEADER_WORDS = (
    ("no data rows after the header", "the table has no rows"),
    ("(header has: ", "(the table has: "),
)


def _columns_of(data: Any):
    """(name, dict of column -> sequence) of a DataFrame or a mapping of arrays."""
    try:
        import pandas as pd  # noqa: F401

        if isinstance(data, pd.DataFrame):
            return "<DataFrame>", {str(k): data[k].tolist() for k in data.columns}
    except ImportError:
        pass
    if isinstance(data, Mapping):
        out = {}
        for k, v in data.items():
            a = np.asarray(v)
            out[str(k)] = a.tolist() if a.ndim == 1 else [a.tolist()] if a.ndim == 0 else None
            if out[str(k)] is None:
                raise InputError(f"<dict>: column '{k}' is not one-dimensional (shape {a.shape})")
        return "<dict>", out
    raise TypeError(
        "data: expected a CSV path, a dict of arrays or a pandas DataFrame, "
        f"not {type(data).__name__}"
    )


def frame(columns: Mapping[str, Sequence[Any]]):
    """A pandas DataFrame of the columns when pandas is installed, else a list of row dicts."""
    try:
        import pandas as pd
    except ImportError:
        keys = list(columns)
        n = len(columns[keys[0]]) if keys else 0
        return [{k: columns[k][i] for k in keys} for i in range(n)]
    return pd.DataFrame(dict(columns))

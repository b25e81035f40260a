"""Reading rocklab's CSV outputs into NumPy structured arrays and tables (SI units in the column
names: *_Pa, *_m, *_s, *_J, *_N)."""
import csv
import os

import numpy as np


def _column(values):
    """A column as float64 when every cell is a number (empty cells: NaN), else as str."""
    try:
        return np.array([float(v) if v != "" else np.nan for v in values], dtype=np.float64)
    except ValueError:
        return np.array(values, dtype=str)


def read_columns(path):
    """The CSV file at `path` as (names, columns): the header's names in order and one 1-D array
    per column (float64, or str for a text column such as a crack's mode)."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    if not rows:
        return [], []
    names = rows[0]
    body = rows[1:]
    return names, [_column([r[i] if i < len(r) else "" for r in body]) for i in range(len(names))]


def read_structured(path):
    """The CSV file at `path` as a NumPy structured array with the header's column names
    (`a["axial_stress_Pa"]`, `a.dtype.names`); an empty array when the file is absent."""
    if not os.path.exists(path):
        return np.zeros(0, dtype=[])
    names, columns = read_columns(path)
    if not names:
        return np.zeros(0, dtype=[])
    return np.rec.fromarrays(columns, names=names).view(np.ndarray)


def read_table(path):
    """The CSV file at `path` as a pandas DataFrame when pandas is installed, else as a dict of
    column name -> 1-D NumPy array (the header's order)."""
    names, columns = read_columns(path)
    table = dict(zip(names, columns))
    try:
        import pandas
    except ImportError:
        return table
    return pandas.DataFrame(table, columns=names)

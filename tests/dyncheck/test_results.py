"""dyncheck.results: reading a CSV's text columns."""

from __future__ import annotations

import io
import warnings

import pandas as pd
import pytest

from dyncheck.results import texts

CSV = "integrator,dt,label\n,0.001,rk4\n,,\n,2,x\n"
"""An integrator column empty in every row (pandas reads it as floats), a numeric column with
an empty cell, a text column with one."""


@pytest.mark.parametrize(
    ("column", "expected"),
    [("integrator", ["", "", ""]), ("dt", ["0.001", "", "2.0"]), ("label", ["rk4", "", "x"])],
)
def test_texts_reads_empty_cells_as_empty_strings_without_a_pandas_warning(column, expected):
    frame = pd.read_csv(io.StringIO(CSV))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # pandas 3 warns (and pandas 4 raises) on fillna("")
        assert texts(frame[column]).tolist() == expected

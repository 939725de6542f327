"""dyncheck.results: reading a CSV's text columns."""

from __future__ import annotations

import io
import os
import stat
import warnings

import numpy as np
import pandas as pd
import pytest

from dyncheck.results import Discrepancy, texts

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


ROW_KINDS = {"dyncheck/results.py": "Discrepancy.measured and .unmeasured",
             "dyncheck/studies/derivatives.py": "a derivative row: a relative error only"}
"""Where a :class:`Discrepancy` is built field by field: its constructors, and the one kind
of row whose error is only relative."""


def test_rows_are_built_by_their_constructors():
    """#43: a row is made by ``Discrepancy.measured`` (an error relative to a scale) or
    ``Discrepancy.unmeasured`` (skipped, or failed before a number), so that the fields a
    kind of row leaves empty are left empty alike everywhere."""
    import ast
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    by_hand = []
    for path in sorted(root.joinpath("dyncheck").rglob("*.py")):
        where = path.relative_to(root).as_posix()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id == "Discrepancy" and where not in ROW_KINDS):
                by_hand.append(f"{where}:{node.lineno}")
    assert not by_hand, by_hand


def test_a_measured_row_is_relative_to_its_scale_and_an_unmeasured_one_has_no_numbers():
    row = Discrepancy.measured(case="c", quantity="mass_matrix", impl_a="a", impl_b="b",
                               error=2e-15, scale=4.0, tolerance=1e-14, basis="round-off",
                               verdict="passed")
    assert row.max_rel_err == 5e-16 and row.integrator == "" and row.worst_state == -1
    gone = Discrepancy.unmeasured(case="c", quantity="trajectory", impl_a="a", impl_b="b",
                                  verdict="skipped", note="needs the 'drake' extra")
    assert np.isnan(gone.max_abs_err) and np.isnan(gone.max_rel_err)
    assert gone.tolerance_basis == "" and gone.worst_state == -1


def test_a_report_is_replaced_as_a_whole_or_not_at_all(tmp_path, monkeypatch):
    """#60: a file-size limit hit while a report was overwritten left the new CSVs beside
    the old README.md. ``write_together`` writes every file beside its target first: the
    third write failing (EFBIG) leaves every old file as it was and no temporary file; a
    write that succeeds replaces them all."""
    import errno
    import os

    from dyncheck.results import write_together

    old = {tmp_path / "a.csv": "old a", tmp_path / "README.md": "old readme"}
    for path, text in old.items():
        path.write_text(text)
    new = {tmp_path / "a.csv": "new a", tmp_path / "figures" / "f.png": b"png",
           tmp_path / "README.md": "new readme"}
    real, calls = os.fdopen, []

    def limited(fd, mode):
        calls.append(fd)
        if len(calls) == 3:
            os.close(fd)
            raise OSError(errno.EFBIG, "File too large")
        return real(fd, mode)

    monkeypatch.setattr("dyncheck.results.os.fdopen", limited)
    with pytest.raises(OSError, match="File too large"):
        write_together(new)
    assert {p.name: p.read_text() for p in old} == {"a.csv": "old a", "README.md": "old readme"}
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["README.md", "a.csv"]
    monkeypatch.setattr("dyncheck.results.os.fdopen", real)
    write_together(new)
    assert (tmp_path / "README.md").read_text() == "new readme"
    assert (tmp_path / "figures" / "f.png").read_bytes() == b"png"


@pytest.mark.parametrize("umask", [0o022, 0o002, 0o077])
@pytest.mark.parametrize("together", [False, True])
def test_a_written_file_has_the_mode_the_umask_gives(tmp_path, umask, together):
    """#80: every file was 0600 (mkstemp's mode survived the rename), so CI artifacts and
    shared report folders were unreadable to others. Expected: 0666 less the umask, as
    ``open()`` would create it (the same rule the kernel applies: an independent file made
    with ``open`` under the same umask is the oracle)."""
    from dyncheck.results import write_atomic, write_together

    old = os.umask(umask)
    try:
        (tmp_path / "plain").write_text("x")
        target = tmp_path / "sub" / "page.md"
        if together:
            write_together({target: "x", tmp_path / "other.csv": b"y"})
        else:
            write_atomic(target, "x")
    finally:
        os.umask(old)
    expected = stat.S_IMODE((tmp_path / "plain").stat().st_mode)
    assert stat.S_IMODE(target.stat().st_mode) == expected == 0o666 & ~umask

"""The verification report: Markdown pages, PNG figures and the CSV tables, written atomically.

:mod:`dyncheck.provenance` (versions), :mod:`.tables` (pandas frames), :mod:`.figures` (PNG),
:mod:`.pages` (Markdown), :mod:`.folder` (render, check, write).
"""

from __future__ import annotations

from dyncheck.provenance import versions
from dyncheck.report.folder import check, render, rendered_text, write
from dyncheck.report.pages import case_page, conventions_page, index_page

__all__ = [
    "case_page",
    "check",
    "conventions_page",
    "index_page",
    "render",
    "rendered_text",
    "versions",
    "write",
]

"""The verification report: Markdown pages, PNG figures and the CSV tables, written atomically.

:mod:`.tables` (pandas frames), :mod:`.figures` (PNG), :mod:`.pages` (Markdown),
:mod:`.folder` (render, check, write: what the commands call); the versions a report records
are :func:`dyncheck.provenance.versions`.
"""

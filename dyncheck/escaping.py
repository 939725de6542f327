"""Text from a user's file made safe for the pages: the one place Markdown and CSV escape.

A model's link, joint and body names, its file name and the engines' messages quoting them
are untrusted input. In Markdown, ``|`` would split a table's cells, a newline add rows or
headings, ``<…>`` reach the page as raw HTML and ``[…](…)`` make a link; in a CSV, a cell
starting with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return is a formula to a
spreadsheet (OWASP's "CSV injection"). Ordinary names (letters, digits, ``_ - . : /`` and
spaces) pass through unchanged, and so do numbers (``-0.5`` is a number, not a formula).
"""

from __future__ import annotations

import math
import re

import pandas as pd

_MARKDOWN = {"\\": "\\\\", "|": "\\|", "`": "\\`", "](": "]\\(", "*": "\\*", "<": "&lt;"}
"""What is escaped: ``<`` alone opens HTML (``>`` and ``&`` cannot: an entity only shows a
character), ``](`` a link or an image, the rest Markdown's own syntax in a line."""
_MARKDOWN_RE = re.compile("|".join(re.escape(c) for c in _MARKDOWN))
_LINE_BREAKS = re.compile(r"[\r\n\u2028\u2029\x0b\x0c\x85]+")
_CONTROL = re.compile(r"[\x00-\x08\x0e-\x1f\x7f]")
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


_SHOWN_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")


def _decoded(text: str) -> str:
    """Bytes of a file name that are not UTF-8 (surrogate escapes) as U+FFFD: a page, a CSV
    cell, is UTF-8 text."""
    return text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")


def shown(text: str) -> str:
    """A name from the file system as dyncheck shows and writes it anywhere (pages, CSV,
    JUnit, JSON, file names, the terminal): bytes that are not UTF-8 (Python's surrogate
    escapes) as U+FFFD, control characters as ``\\xNN`` (a terminal escape in a file name
    never reaches a terminal; XML cannot hold them)."""
    return _SHOWN_CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", _decoded(text))


def markdown(text: object) -> str:
    """``text`` as literal Markdown: one line, no table cell break, no HTML, no link."""
    one_line = _LINE_BREAKS.sub(" ", _CONTROL.sub("", _decoded(str(text))))
    return _MARKDOWN_RE.sub(lambda m: _MARKDOWN[m.group()], one_line)


def markdown_code(text: object) -> str:
    """``text`` in a code span where it can be one (no backtick, no line break, no pipe),
    else as escaped plain text."""
    s = _decoded(str(text))
    if _LINE_BREAKS.search(s) or _CONTROL.search(s) or any(c in s for c in "`|"):
        return markdown(s)
    return f"`{s}`"


def _number(text: str) -> bool:
    try:
        return not math.isnan(float(text)) or text.strip().lower() in ("nan", "-nan", "+nan")
    except ValueError:
        return False


def csv_cell(text: str) -> str:
    """A text cell that no spreadsheet reads as a formula: a leading ``'`` where it starts
    with one of :data:`FORMULA_STARTS` and is not a number."""
    text = _decoded(text)
    if text.startswith(FORMULA_STARTS) and not _number(text):
        return "'" + text
    return text


def csv_safe(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with every text cell through :func:`csv_cell` (numbers untouched)."""
    out = frame.copy()
    for column in out.columns:
        if out[column].dtype == object or pd.api.types.is_string_dtype(out[column]):
            out[column] = out[column].map(lambda v: csv_cell(v) if isinstance(v, str) else v)
    return out


def markdown_link(text: object, target: str) -> str:
    """A link whose text is escaped and whose target is percent-encoded (a file name from a
    user's model cannot close the link or add one)."""
    from urllib.parse import quote

    return f"[{markdown(text)}]({quote(target)})"


def markdown_table(frame: pd.DataFrame, *, escaped: tuple[str, ...] = (),
                   **options: object) -> str:
    """``frame.to_markdown`` with every text cell and column name through :func:`markdown`,
    except the columns ``escaped`` (built from escaped parts by the caller: links)."""
    shown = frame.copy()
    for column in shown.columns:
        if column in escaped:
            continue
        if shown[column].dtype == object or pd.api.types.is_string_dtype(shown[column]):
            shown[column] = shown[column].map(lambda v: markdown(v) if isinstance(v, str) else v)
    shown.columns = [markdown(c) for c in shown.columns]
    return shown.to_markdown(index=False, **options)


MAX_NAME = 200
"""Bytes of a page name at most, as UTF-8 (a file name's limit is 255 bytes; the suffix and
the numbering need the rest)."""


def file_name(text: str) -> str:
    """``text`` as one safe file name in an output folder: shown as dyncheck shows names
    (:func:`~dyncheck.escaping.shown`), with no path separator, no leading dot (no hidden
    file, no ``..``), never empty, at most :data:`MAX_NAME` bytes."""
    name = shown(text).replace("/", "__")
    name = name.lstrip(".").strip() or "model"
    return name.encode()[:MAX_NAME].decode(errors="ignore")

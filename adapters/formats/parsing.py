"""A model file's XML as the engines' parsers read it. MuJoCo's, Pinocchio's (urdfdom),
Drake's and PyBullet's parsers (TinyXML) do no namespace processing: an attribute or element
with a prefix the file never declares (``drake:acceleration``, ``<drake:collision_filter_group>``,
``<gazebo>``'s ``xacro:`` leftovers) is a name like any other to them. Python's parser
(expat) refuses it ("unbound prefix"): dyncheck declares each such prefix on the root, as a
namespace of its own (:data:`UNDECLARED`), and reads on — a file every engine loads is never
refused by dyncheck's pre-read (#77). A file in another encoding than UTF-8, which every
engine's MJCF parser assumes, is named by :func:`encoding` (its copy for the parsers:
:func:`~.mjcf_copy.utf8_file`)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path
from pyexpat import errors

UNDECLARED = "urn:dyncheck:undeclared:"
"""The namespace an undeclared prefix ``p`` is given: ``urn:dyncheck:undeclared:p``."""

_PREFIXED = re.compile(rb"[<\s/]([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*")
_DECLARED = re.compile(rb"xmlns:([A-Za-z_][\w.-]*)\s*=")
_ROOT = re.compile(rb"<(?![?!])[A-Za-z_][\w.:-]*")
_UNBOUND = errors.codes[errors.XML_ERROR_UNBOUND_PREFIX]


def root(raw: bytes | str) -> ET.Element:
    """The document's root element; ``ET.ParseError`` where it is not XML even with its
    undeclared prefixes declared."""
    try:
        return ET.fromstring(raw)
    except ET.ParseError as exc:
        if exc.code != _UNBOUND:
            raise
    data = raw.encode("utf-8") if isinstance(raw, str) else raw
    declared = set(_DECLARED.findall(data)) | {b"xml", b"xmlns"}
    prefixes = sorted(set(_PREFIXED.findall(data)) - declared)
    start = _ROOT.search(data)
    if not prefixes or start is None:
        raise ET.ParseError("unbound prefix")
    for prefix in prefixes:  # a copy written back keeps the file's own prefix
        if not re.fullmatch(rb"ns\d+", prefix):  # (ElementTree's own, not registrable)
            ET.register_namespace(prefix.decode(), UNDECLARED + prefix.decode())
    added = b"".join(b' xmlns:%s="%s%s"' % (p, UNDECLARED.encode(), p) for p in prefixes)
    return ET.fromstring(data[:start.end()] + added + data[start.end():])


def encoding(path: Path) -> str | None:
    """The encoding an MJCF file declares, where it is not UTF-8 (None for a UTF-8 file)."""
    raw = path.read_bytes()
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError:
        pass
    else:
        return None
    declared = re.search(rb"encoding\s*=\s*[\"']([^\"']+)", raw[:400].replace(b"\0", b""))
    if declared:
        return declared.group(1).decode("ascii", "replace")
    return "UTF-16" if raw[:2] in (b"\xff\xfe", b"\xfe\xff") else "not UTF-8"


def transcoded(declared: str) -> str:
    """The page's note for a file every engine was given as a UTF-8 copy."""
    return (f"the file is encoded as {declared}, and every engine's MJCF parser reads UTF-8: "
            "each was given a UTF-8 copy decoded as the file declares (includes inlined, "
            "asset paths made absolute)")

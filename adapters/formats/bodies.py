"""A name for every body of an MJCF, the unnamed ones included: its own, else its place among
the file's bodies (``#k``), which is MuJoCo's body id — its compiler numbers bodies in
document order, depth first, the world 0 (measured: the compiled ``body_parentid`` of a file
with unnamed bodies follows their order in the file). A fix that states what MuJoCo compiled
for a body finds it by this key in a copy of the file (#77)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

UNNAMED = "#{index}"
"""The key of an unnamed body: its MuJoCo body id."""


def key(name: str, index: int) -> str:
    """A body's key from its name and its MuJoCo body id."""
    return name or UNNAMED.format(index=index)


def keys(root: ET.Element) -> dict[int, str]:
    """Each ``<body>`` of ``root`` (its includes inlined), by ``id()`` of its element: its
    key (:func:`key`)."""
    return {id(body): key(body.get("name", ""), k)
            for k, body in enumerate(root.iter("body"), start=1)}

"""An MJCF file's ``<include>``s, inlined as MuJoCo's parser inlines them — a cycle, a missing
or special file (a FIFO, a device) found here, never handed to a parser that can loop or block
on it — and the files its assets name, resolved as MuJoCo resolves them (the compiler's
``meshdir``, ``texturedir``, ``assetdir``; an included file's asset beside the included file
where the main file's folder has none) — and the model made standalone (:func:`standalone`: its
asset paths absolute)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from dyncheck.adapters.formats import parsing
from dyncheck.errors import EngineError
from dyncheck.regular_files import NotRegular, Refusal, open_regular

MAX_INCLUDE_BYTES = 64 * 2**20
MAX_INCLUDE_DEPTH = 32


def compiler(root: ET.Element, key: str, default: str) -> str:
    """The compiler's ``key`` (the last ``<compiler>`` that states it), else ``default``."""
    value = default
    for element in root.iter("compiler"):
        value = element.get(key, value)
    return value


ASSET_DIRS = {"mesh": "meshdir", "skin": "meshdir", "hfield": "meshdir",
              "texture": "texturedir"}
"""The compiler attribute each asset's file is relative to (``assetdir`` where it is absent)."""
ASSET_TAGS = (*ASSET_DIRS, "model")
"""The elements that name a file: the assets, and a model to attach."""
FILE_KEYS = ("file", "fileright", "fileleft", "fileup", "filedown", "filefront", "fileback")
"""The attributes that name a file on an asset (a cube texture names one per face)."""


def asset_file(root: ET.Element, folder: Path, element: ET.Element,
               key: str = "file") -> Path | None:
    """The absolute path of the file ``element``'s ``key`` names, relative to ``folder`` and
    the compiler's asset folders; None where it names none."""
    file = element.get(key)
    if not file:
        return None
    base = compiler(root, ASSET_DIRS.get(element.tag, "assetdir"),
                    compiler(root, "assetdir", ""))
    return (folder / base / file).resolve()


def _read(path: Path, including: Path) -> ET.Element:
    """An included file's root, read only if it is a regular file (a FIFO or a device would
    block or never end)."""
    where = f"{including}: <include file={path.name!r}>"
    try:
        with open_regular(path, follow=True, most=MAX_INCLUDE_BYTES) as handle:
            raw = handle.read()
    except FileNotFoundError as exc:
        raise EngineError(f"{where}: cannot be read ({exc.strerror})") from None
    except NotRegular as exc:
        raise EngineError(where + {
            Refusal.UNOPENABLE: f": cannot be read ({exc.reason})",
            Refusal.NOT_REGULAR: ": not a regular file",
            Refusal.TOO_LARGE: f": larger than {MAX_INCLUDE_BYTES // 2**20} MiB"}[exc.refusal]
        ) from None
    try:
        return parsing.root(raw)
    except ET.ParseError as exc:
        raise EngineError(f"{path}: not XML ({exc})") from None


def equalities(root: ET.Element) -> list[ET.Element]:
    """The model's equality constraints (``root``: inlined), in the file's order: every
    ``<equality>`` block's children."""
    return [item for block in root.findall("equality") for item in block]


def inline(path: Path) -> ET.Element:
    """The model's root with every ``<include>`` replaced by the included file's children
    (paths relative to the main file's folder, as MuJoCo resolves them, else to the including
    file's)."""
    main = path.resolve()

    def expand(start: ET.Element, origin: tuple[Path, ...]) -> None:
        pending = [(start, origin)]  # (elements without recursion: trees 1000 bodies deep)
        while pending:
            element, chain = pending.pop()
            _expand_one(element, chain, pending)

    def _expand_one(element: ET.Element, chain: tuple[Path, ...],
                    pending: list[tuple[ET.Element, tuple[Path, ...]]]) -> None:
        children = list(element)
        for index, child in reversed(list(enumerate(children))):
            if child.tag != "include":
                pending.append((child, chain))
                continue
            name = child.get("file", "")
            if not name.strip():
                raise EngineError(f"{chain[-1]}: <include> has no file attribute")
            target = (main.parent / name).resolve()
            if not target.exists():  # older files: relative to the including file
                target = (chain[-1].parent / name).resolve()
            if target in chain:
                raise EngineError(f"{chain[-1]}: <include file={name!r}> includes itself "
                                  "(an include cycle)")
            if len(chain) > MAX_INCLUDE_DEPTH:
                raise EngineError(f"{chain[-1]}: includes nested deeper than "
                                  f"{MAX_INCLUDE_DEPTH}")
            included = _read(target, chain[-1])
            origins.extend((e, target.parent) for e in included.iter() if e.tag in ASSET_DIRS)
            expand(included, (*chain, target))  # (recursion only per include: at most 32)
            element.remove(child)
            for offset, part in enumerate(included):
                element.insert(index + offset, part)

    origins: list[tuple[ET.Element, Path]] = []
    root = _read(main, main)
    expand(root, (main,))
    for element, folder in origins:  # MuJoCo (4.0, measured): the main file's folder first,
        found = asset_file(root, main.parent, element)  # else the included file's
        beside = asset_file(root, folder, element)
        if found is not None and beside is not None and not found.exists() and beside.exists():
            element.set("file", str(beside))
    return root


def _asset_attributes(root: ET.Element, folder: Path
                      ) -> list[tuple[ET.Element, str, Path]]:
    """Every file attribute of the (inlined) model's assets — meshes, skins, height fields,
    textures (each face of a cube), attached models — with the absolute path MuJoCo resolves
    it to (the compiler's asset folders)."""
    return [(element, key, path) for element in root.iter() if element.tag in ASSET_TAGS
            for key in FILE_KEYS if (path := asset_file(root, folder, element, key))]


def asset_files(root: ET.Element, folder: Path) -> list[tuple[str, Path]]:
    """Every file the model's assets name, as ``(<element attribute>, absolute path)``."""
    return [(f"<{e.tag} {key}>", path) for e, key, path in _asset_attributes(root, folder)]


def standalone(root: ET.Element, folder: Path) -> str:
    """The (inlined) model as text whose asset files are absolute paths, so that it reads the
    same from anywhere: the compiler's asset folders folded into them."""
    for element, key, path in _asset_attributes(root, folder):
        element.set(key, str(path))
    for settings in root.iter("compiler"):
        for key in ("meshdir", "texturedir", "assetdir"):
            settings.attrib.pop(key, None)
    return ET.tostring(root, encoding="unicode")

"""What ``dyncheck check`` is given, validated before any engine runs: every fault is one line
naming the file (and the element, line or engine where known)."""

from __future__ import annotations

import importlib.metadata
import os
import xml.etree.ElementTree as ET
from pathlib import Path

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.files import (
    INERTIA_KEYS,
    ROOT_TAG,
    ModelFile,
    urdf_inertials,
    urdf_links,
    urdf_welded,
)
from dyncheck.adapters.formats.includes import asset_files, inline
from dyncheck.adapters.registration import Format
from dyncheck.errors import EngineError, InvalidInput, UnknownName

URDF_JOINTS = ("revolute", "continuous", "prismatic", "fixed", "floating", "spherical")
"""The URDF joint types checked (``floating``: a free joint in MuJoCo's and Pinocchio's
parsers, given as one to Drake, whose parser leaves a free body; ``spherical``, PyBullet's
extension: a ball joint in PyBullet's and MuJoCo's parsers, refused by Pinocchio's and
Drake's — their load rows say so; ``planar`` is not checked: Pinocchio's parser maps it,
MuJoCo's refuses or changes it)."""
MAX_STATES = 100_000
ROBOTS_EXTRA = "example-robot-data"


class ModelFileError(InvalidInput):
    """A model file that cannot be checked: one line naming the file."""

    def __init__(self, path: Path | str, problem: str) -> None:
        self.field, self.value, self.expected = "model", str(path), problem
        Exception.__init__(self, f"{path}: {problem}")


def model_path(text: str) -> Path:
    """An existing, readable MJCF (``<mujoco>``) or URDF (``<robot>``) file."""
    path = Path(text)
    if not path.exists():
        raise ModelFileError(path, "no such file")
    if not path.is_file():
        raise ModelFileError(path, "not a file")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ModelFileError(path, f"cannot be read ({exc.strerror})") from None
    try:
        root = parsing.root(raw)
    except ET.ParseError as exc:
        line, column = exc.position
        raise ModelFileError(path, f"not XML (line {line}, column {column})") from None
    except LookupError as exc:  # <?xml encoding="..."?> that Python does not know
        raise ModelFileError(path, f"not XML: it declares an encoding no parser knows "
                             f"({exc})") from None
    if root.tag == ROOT_TAG[Format.URDF]:
        _check_urdf(path, root)
    elif root.tag != ROOT_TAG[Format.MJCF]:
        raise ModelFileError(path, f"root element <{root.tag}> is neither <mujoco> nor <robot>")
    else:  # an include cycle or a FIFO would hang a parser: refused before any engine runs
        if path.suffix != ".xml":  # MuJoCo picks its decoder by the suffix, case and all
            raise ModelFileError(path, f"an MJCF must be named *.xml for MuJoCo, which picks "
                                 f"its parser by the file's suffix (rename it; got "
                                 f"{path.suffix or 'no suffix'!r})")
        try:
            inlined = inline(path)
        except EngineError as exc:
            raise ModelFileError(path, str(exc).removeprefix(f"{path.resolve()}: ")) from None
        for where, asset in asset_files(inlined, path.resolve().parent):
            if asset.exists() and not asset.is_file():  # a FIFO never ends; a device neither
                raise ModelFileError(path, f"{where} names {asset.name!r}, which is not a "
                                     f"regular file ({_kind(asset)}): no engine may open it")
        deepest = nesting(inlined)
        if deepest > MAX_NESTING:
            raise ModelFileError(path, f"XML elements nested {deepest} deep (the check walks "
                                 f"trees at most {MAX_NESTING} deep; split the model)")
    if root.tag == "robot" and (deepest := _chain_depth(root)) > MAX_NESTING:
        raise ModelFileError(path, f"links chained {deepest} deep (the check walks trees "
                             f"at most {MAX_NESTING} deep; split the model)")
    _stack_holds(path, deepest if root.tag == "robot" else nesting(inlined))
    return path


STACK_BASE_MIB = 1.0
STACK_PER_LEVEL_KIB = 16.0
"""The stack a check needs: a base and so much per level of the tree (its walks, the
pickling of a tree for an engine's process and the parsers recurse through C, level by
level). Measured: a 200-level MJCF chain ended dyncheck in a segmentation fault under a
2 MiB stack and passed under 4 MiB; 400 levels failed under 4 MiB (10 to 20 KiB a level)."""


def _stack_holds(path: Path, levels: int) -> None:
    """Refuse up front a tree deeper than this process's stack holds once its soft limit is
    raised as far as the hard one allows (:func:`~dyncheck.confinement.stack_room`; the
    command does so first, the Python API here)."""
    from dyncheck import confinement

    confinement.stack_room()  # (what the hard limit allows, in this process too)
    have = confinement.stack_mib()
    need = STACK_BASE_MIB + levels * STACK_PER_LEVEL_KIB / 1024
    if have is not None and have < need:
        raise ModelFileError(path, f"a tree {levels} levels deep needs about {need:.1f} MiB "
                             f"of stack, more than this process's {have} MiB (ulimit -s; "
                             "raise it, e.g. ulimit -s unlimited)")


def _kind(path: Path) -> str:
    """What a path that is not a regular file is, in a word."""
    import stat

    mode = path.stat().st_mode
    for test, word in ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISSOCK, "a socket"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISDIR, "a folder")):
        if test(mode):
            return word
    return "a special file"


MAX_NESTING = 2000
"""The deepest tree the check walks (its walks recurse body by body: Python's recursion
limit is raised for them, :func:`dyncheck.__main__.main`); a deeper one is refused up front."""


def nesting(root: ET.Element) -> int:
    """The deepest nesting of XML elements under ``root``, walked without recursion."""
    deepest, stack = 0, [(root, 1)]
    while stack:
        element, depth = stack.pop()
        deepest = max(deepest, depth)
        stack.extend((child, depth + 1) for child in element)
    return deepest


def _chain_depth(root: ET.Element) -> int:
    """The longest parent-child chain of a URDF's joints, walked without recursion."""
    parent_of = {}
    for joint in root.findall("joint"):
        p, c = joint.find("parent"), joint.find("child")
        if p is not None and c is not None:
            parent_of[c.get("link", "")] = p.get("link", "")
    deepest = 0
    for link in parent_of:
        seen, at = set(), link
        while at in parent_of and at not in seen:
            seen.add(at)
            at = parent_of[at]
        deepest = max(deepest, len(seen))
    return deepest


XACRO = "{http://www.ros.org/wiki/xacro}"
"""xacro's XML namespace: its elements in a file mean the file is a template, not a URDF."""


def _check_urdf(path: Path, root: ET.Element) -> None:
    xacro = next((e.tag.removeprefix(XACRO) for e in root.iter()
                  if isinstance(e.tag, str) and e.tag.startswith(XACRO)), None)
    if xacro is not None or any("${" in value for e in root.iter() for value in e.attrib.values()):
        what = f"<xacro:{xacro}>" if xacro else "a ${…} expression"
        raise ModelFileError(path, f"is an unexpanded xacro file ({what}): the engines would "
                             "read its plain parts only; expand it first (xacro FILE > "
                             "robot.urdf)")
    for joint in root.findall("joint"):  # not <transmission>'s <joint> references
        kind = joint.get("type", "")
        if kind not in URDF_JOINTS:
            raise ModelFileError(
                path,
                f"joint {joint.get('name')!r} has type {kind!r}, which is not checked "
                f"(checked: {', '.join(URDF_JOINTS)})",
            )
    for link in root.findall("link"):  # the inertials the check reads itself, as numbers
        for tag, keys in (("mass", ("value",)), ("inertia", INERTIA_KEYS)):
            element = link.find(f"inertial/{tag}")
            for key in keys if element is not None else ():
                text = element.get(key, "0")  # type: ignore[union-attr]
                try:
                    float(text)
                except ValueError:
                    raise ModelFileError(path, f"link {link.get('name')!r}: <{tag} {key}="
                                         f"{text!r}> is not a number") from None


def states(value: int) -> int:
    if not 1 <= value <= MAX_STATES:
        raise InvalidInput("--states", value, f"an integer in [1, {MAX_STATES}]")
    return value


MEMORY_SHARE = 0.5
"""The share of this machine's memory a check's arrays may take."""


def machine_memory() -> int:
    """Bytes of physical memory (0 where the system does not say)."""
    try:
        return int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return 0


def fits_in_memory(*, count: int, nv: int, arrays: int, flag: str = "--states") -> None:
    """Refuse, before the work, a check whose ``arrays`` arrays of ``count`` states × nv²
    doubles (the mass matrices every implementation returns, and the referee's on every
    engine's reading) would take more than :data:`MEMORY_SHARE` of this machine's memory: a
    100 000-state check of a 100-joint chain died with numpy's ArrayMemoryError after the
    engines had run."""
    total = machine_memory()
    need = count * nv * nv * 8 * arrays
    if total and need > MEMORY_SHARE * total:
        most = max(1, int(MEMORY_SHARE * total // (nv * nv * 8 * arrays)))
        raise InvalidInput(flag, count, (
            f"at most {most} states for this model: {nv} degrees of freedom at {count} states "
            f"need {need / 2**30:.1f} GiB for {arrays} arrays of states × nv² doubles, more "
            f"than {MEMORY_SHARE:.0%} of this machine's {total / 2**30:.1f} GiB"))


def robots_folder() -> Path | None:
    """example-robot-data's ``robots`` folder, or None when the ``robots`` extra is absent."""
    try:
        dist = importlib.metadata.distribution(ROBOTS_EXTRA)
    except importlib.metadata.PackageNotFoundError:
        return None
    folder = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
    return folder if folder.is_dir() else None


def robots() -> dict[str, Path]:
    """Every URDF of example-robot-data by name: the file's stem, or ``folder/stem`` where
    two folders hold the same stem."""
    folder = robots_folder()
    if folder is None:
        return {}
    files = sorted(folder.rglob("*.urdf"))
    stems: dict[str, int] = {}
    for f in files:
        stems[f.stem] = stems.get(f.stem, 0) + 1
    out = {}
    for f in files:
        top = f.relative_to(folder).parts[0].removesuffix("_description")
        out[f.stem if stems[f.stem] == 1 else f"{top}/{f.stem}"] = f
    return out


def robot(name: str) -> Path:
    available = robots()
    if not available:
        from dyncheck.errors import install_hint

        raise InvalidInput(
            "--robot", name, "a robot of example-robot-data: " + install_hint("robots")
        )
    if name not in available:
        raise UnknownName("robot", name, available)
    return available[name]


def massive(path: Path, source: ModelFile) -> None:
    """A URDF none of whose moving links states a positive mass is refused before any engine
    runs: every moving body would be massless, M zero or singular, the dynamics undefined."""
    if source.format.value != "urdf":
        return
    welded = urdf_welded(source)
    links = urdf_links(source)
    if links <= welded:  # nothing moves: the check's own refusal says so
        return
    if not any(i.mass > 0 for i in urdf_inertials(source) if i.link not in welded):
        raise ModelFileError(
            path, "no moving link states an <inertial> with a positive mass: every moving "
            "body is massless and its dynamics undefined (fix: give each moving link an "
            "<inertial> with its mass and inertia)")

"""Where dyncheck runs from — a checkout of its repository (an editable install) or an
installed package (a wheel) — and how an optional extra is installed from there: dyncheck is
not on a package index, so a hint names the extra's own packages, which are."""

from __future__ import annotations

import re
from pathlib import Path

from dyncheck.errors import DyncheckError

ROOT = Path(__file__).resolve().parents[1]
"""The repository root when dyncheck runs from a checkout; site-packages when installed."""


class NeedsCheckout(DyncheckError):
    """A command that works on the repository's own files (the tutorials' sources, the pins
    of ``constraints.txt``, the committed reports) run from an installed package."""

    def __init__(self, what: str) -> None:
        super().__init__(f"{what} needs a checkout of the dyncheck repository (git clone it "
                         "and `pip install -e .` there); the installed package holds the code "
                         "alone")


def checkout() -> Path | None:
    """The repository's root where dyncheck runs from a checkout, else None."""
    looks = (ROOT / "pyproject.toml").is_file() and (ROOT / "dyncheck").is_dir() \
        and (ROOT / "tutorials").is_dir()
    return ROOT if looks else None


def needs_checkout(what: str) -> Path:
    """The checkout's root, or :class:`NeedsCheckout` naming ``what`` needs it."""
    root = checkout()
    if root is None:
        raise NeedsCheckout(what)
    return root


def install_hint(extra: str) -> str:
    """How to add the optional extra ``extra`` where dyncheck is now: from a checkout, the
    extra itself; installed, the extra's packages with their version ranges, read from the
    installed metadata (``pip install 'dyncheck[…]'`` finds no dyncheck on a package index)."""
    root = checkout()
    if root is not None:
        return f"pip install -c constraints.txt -e '.[{extra}]' in the checkout"
    packages = extra_packages(extra)
    if not packages:
        return f"install the packages of dyncheck's extra {extra!r}"
    return "pip install " + " ".join(f"'{p}'" for p in packages)


def extra_packages(extra: str) -> list[str]:
    """The requirements dyncheck's installed metadata lists for ``extra`` (empty where the
    metadata cannot be read)."""
    from importlib.metadata import PackageNotFoundError, requires

    try:
        listed = requires("dyncheck") or []
    except PackageNotFoundError:
        return []
    marker = re.compile(r"""extra\s*==\s*["']([^"']+)["']""")
    out = []
    for line in listed:
        requirement, _, condition = line.partition(";")
        found = marker.search(condition)
        if found is not None and found.group(1) == extra:
            out.append(requirement.strip().replace(" ", ""))
    return out

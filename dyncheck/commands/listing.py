"""``dyncheck list``: cases, implementations with their versions, robots."""

from __future__ import annotations

import argparse

from dyncheck.commands.flags import Command
from dyncheck.errors import EngineNotInstalled, install_hint


def installed_version(package: str) -> str | None:
    """An installed distribution's version, read from its metadata (nothing imported)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return None


def engine_line(name: str) -> str:
    """An engine imported: its version (and device, for a port) and its integrators."""
    from dyncheck.adapters import ENGINE_PACKAGES, REGISTRY
    from dyncheck.adapters.installed import engine_version, get_engine
    from dyncheck.adapters.offers import Offer
    from dyncheck.studies.order import CONTROLLED  # (the studies' package imports sympy)

    try:
        offers = get_engine(name).offers
    except EngineNotInstalled as exc:  # the hint names the package or the extra
        return f"not installed: {exc.hint}"
    steps = list(REGISTRY[name].integrators)
    if Offer.SOLVING in offers:
        steps.append("dop853 (scipy, error-controlled)")
    if Offer.CONTROLLED_STEPPING in offers:
        steps.append(f"{CONTROLLED} (its own runge_kutta3, error-controlled)")
    return f"{ENGINE_PACKAGES[name]} {engine_version(name)}; integrators: {', '.join(steps)}"


def list_command(*, integrators: bool = False) -> int:
    """Cases, implementations and robots. Engines are named with their installed version from
    the package metadata — fast, nothing imported — or, with ``integrators``, imported."""
    from dyncheck.adapters import ENGINE_EXTRAS, ENGINE_PACKAGES, NOT_ADDED
    from dyncheck.cases import CASES
    from dyncheck.cases import NOT_ADDED as CASES_NOT_ADDED
    from dyncheck.roster import IMPLEMENTATIONS

    print("cases:")
    for name, cls in CASES.items():
        print(f"  {name:24s} {cls.title}")
    for name, why in CASES_NOT_ADDED.items():  # an installed package's case left out
        print(f"  {name:24s} not added: {why}")
    print("implementations:")
    for name in IMPLEMENTATIONS:
        if name == "book":
            what = "dyncheck.reference (book printed equations)"
        elif name not in ENGINE_PACKAGES:
            what = "dyncheck.reference (general method, (2.2.23)-(2.2.26))"
        elif integrators:
            what = engine_line(name)
        elif (version := installed_version(ENGINE_PACKAGES[name])) is not None:
            what = f"{ENGINE_PACKAGES[name]} {version}"
        elif name in ENGINE_EXTRAS:
            what = f"not installed: {install_hint(ENGINE_EXTRAS[name])}"
        else:
            what = f"not installed: pip install {ENGINE_PACKAGES[name]}"
        print(f"  {name:24s} {what}")
    for name, why in NOT_ADDED.items():  # an installed package's engine that did not register
        print(f"  {name:24s} not added: {why}")
    from dyncheck.check.inputs import robots

    found = robots()
    if found:
        print(f"robots (example-robot-data, for `dyncheck check --robot NAME`): {len(found)}")
        for name, path in found.items():
            print(f"  {name:32s} {path.name}")
    else:
        print(f"robots: the 'robots' extra is not installed ({install_hint('robots')})")
    return 0


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--integrators",
        action="store_true",
        help="import each engine: its integrators and, for the ports, the device (slower: "
        "JAX and Warp take seconds to import)",
    )


COMMAND = Command(
    name="list", help="cases and implementations, with installed engine versions",
    example="dyncheck list --integrators", arguments=_arguments,
    handler=lambda args: list_command(integrators=args.integrators))

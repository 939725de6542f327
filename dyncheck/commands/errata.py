"""``dyncheck errata``: every formula of §2.2 checked, the errata page written."""

from __future__ import annotations

import argparse
from pathlib import Path

from dyncheck.commands.flags import Command
from dyncheck.commands.options import check_out_file, path_arg


def errata_command(args: argparse.Namespace) -> int:
    from dyncheck.errata import page
    from dyncheck.results import write_atomic

    check_out_file("--out", args.out)
    write_atomic(args.out, page.page())
    print(f"errata page written to {args.out}")
    return 0


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", type=path_arg, default=Path("reports/errata.md"), metavar="FILE")


COMMAND = Command(
    name="errata", help="check every formula of §2.2 and write the errata page",
    example="dyncheck errata && dyncheck explain erratum-action-integral.d5",
    arguments=_arguments, handler=errata_command)

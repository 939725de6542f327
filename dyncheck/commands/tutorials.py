"""``dyncheck tutorials``: the lessons executed and rendered."""

from __future__ import annotations

import argparse
import sys

from dyncheck.commands import flags
from dyncheck.commands.flags import Command
from dyncheck.commands.options import OUT, check_out, claim_out, path_arg
from dyncheck.errors import UnknownName
from dyncheck.progress import Progress


def tutorials_command(args: argparse.Namespace) -> int:
    """Execute each tutorial (its own checks must hold) and render it; exit 1 if one fails."""
    from dyncheck import tutorials

    known = tutorials.available()
    names = args.names or list(known)
    for name in names:
        if name not in known:
            raise UnknownName("tutorial", name, known)
    check_out(args.out)
    claim_out(args.out)
    failed = 0
    with Progress("tutorials", len(names), quiet=args.quiet) as progress:
        for name in names:
            try:
                nb = tutorials.execute(name)
            except tutorials.TutorialFailed as exc:
                print(f"dyncheck: {exc}", file=sys.stderr)
                failed += 1
                progress.done(f"{name} (failed)")
                continue
            written = tutorials.render(name, nb, args.out)
            print(f"{name}: executed -> {written[0]}")
            progress.done(name)
    if not args.names:
        tutorials.index(args.out)
    return 1 if failed else 0


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("names", nargs="*", metavar="NAME", help="tutorials (default: all)")
    p.add_argument("--out", type=path_arg, default=OUT / "tutorials",
                   help=f"output folder (default: {OUT / 'tutorials'}; the committed pages: "
                   "--out reports/tutorials)")
    flags.quiet(p)


COMMAND = Command(
    name="tutorials", help="execute the tutorials and render them to Markdown",
    example="dyncheck tutorials 01_quaternion_order --out /tmp/tutorials",
    arguments=_arguments, handler=tutorials_command)

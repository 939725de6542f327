"""``dyncheck explain`` and ``dyncheck errata``: the conventions catalogue and the
book's formulas."""

from __future__ import annotations

import argparse
from pathlib import Path

from dyncheck.commands.options import (
    check_out_file,
    positive,
)
from dyncheck.errors import InvalidInput


def explain_command(args: argparse.Namespace) -> int:
    from dyncheck.catalogue import explain_cached, render

    if args.name is not None and args.name.startswith("erratum-"):
        from dyncheck.errata import page

        print(page.explain(args.name.removeprefix("erratum-")))
        return 0
    positive("--jobs", args.jobs)
    if args.reproducer is not None:
        return _reproducer(args.name, args.reproducer)
    entries, read_back = explain_cached(args.name, accelerators=args.accelerators,
                                        jobs=args.jobs)
    print(render(entries))
    if read_back:
        print(f"({read_back} of {len(entries)} measured by an earlier `dyncheck explain` with "
              "the same dyncheck, engines and machine, read from the cache; --no-cache "
              "measures afresh)")
    return 1 if any(e.failed for e in entries) else 0


def _reproducer(name: str | None, out: Path) -> int:
    """``explain NAME --reproducer FILE``: the entry's standalone script, written whole."""
    from dyncheck.escaping import shown  # (pandas: not on `dyncheck list`'s path)
    from dyncheck.explain.reproducers import REPRODUCERS
    from dyncheck.results import write_atomic

    if name is None or name not in REPRODUCERS:
        raise InvalidInput("--reproducer", str(name), "given with a convention that is an "
                           f"engine's defect: one of {', '.join(REPRODUCERS)}")
    check_out_file("--reproducer", out)
    found = REPRODUCERS[name]
    write_atomic(out, found.script)
    print(f"wrote {shown(str(out))}: `python {shown(str(out))}` needs only {found.engine} and "
          "numpy; it prints the expected and the observed value and exits 1 while the defect "
          "stands")
    return 0


def errata_command(args: argparse.Namespace) -> int:
    from dyncheck.errata import page
    from dyncheck.results import write_atomic

    check_out_file("--out", args.out)
    write_atomic(args.out, page.page())
    print(f"errata page written to {args.out}")
    return 0

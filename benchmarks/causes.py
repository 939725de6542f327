"""Every cause a check page names, re-proved (#77's acceptance): ``dyncheck check`` on each
model given (files, or folders walked for ``*.xml`` and ``*.urdf``), every verifier run again
(each hint's fix applied to a copy and read by its engine, :mod:`dyncheck.check.proofs`),
and each row that names a cause counted by where it stands: fix verified; the fix measured
and a gap left (cause unknown, its share stated); suspected (its fix not measured: a cause
dyncheck cannot yet prove). Exits 1 where any row is only suspected, or the check crashed on a
model (a defect of dyncheck's own), naming each.

    python benchmarks/causes.py MODEL_OR_FOLDER... [--impl mujoco,pinocchio,drake]
        [--states 10] [--out causes.md]

Try it on published collections installed as packages (never in the tests): e.g.
``python benchmarks/causes.py $(python -c "import example_robot_data as e; print(e.getModelPath(
'panda_description'))")``. A model no engine loads is counted as refused, not as a failure of
a verifier.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from dyncheck.check.model_check import check_model
from dyncheck.check.proofs import Standing, standing
from dyncheck.errors import DyncheckError
from dyncheck.escaping import markdown_table
from dyncheck.results import write_atomic

SUFFIXES = (".xml", ".urdf")


def models(paths: list[Path]) -> list[Path]:
    """The model files named, folders walked (sorted: the same order on every machine)."""
    out: list[Path] = []
    for path in paths:
        out += sorted(p for p in path.rglob("*") if p.suffix in SUFFIXES) if path.is_dir() \
            else [path]
    return out


CRASHED = "dyncheck crashed (a defect of ours)"


def _one(path: Path, standing: str, note: str) -> pd.DataFrame:
    return pd.DataFrame([{"model": path.name, "impl_b": "", "subject": "", "field": "",
                          "standing": standing, "note": note}])


def causes(path: Path, *, impls: tuple[str, ...], states: int) -> pd.DataFrame:
    """The rows of ``path``'s check that name a cause, with where each stands."""
    try:
        rows = check_model(path, impls=impls, states=states).rows
    except DyncheckError as exc:  # refused by every engine, or not a model: its own row
        return _one(path, "refused", str(exc).splitlines()[0])
    except Exception as exc:  # a defect of dyncheck's own: counted, and the run goes on
        return _one(path, CRASHED, f"{type(exc).__name__}: {exc}")
    rows = rows[rows["note"].astype(str) != ""].copy()
    rows["standing"] = [standing(n).value for n in rows["note"]]
    rows = rows[rows["standing"] != Standing.UNNAMED.value]
    rows["model"] = path.name
    return rows[["model", "impl_b", "subject", "field", "standing", "note"]]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="+", type=Path)
    parser.add_argument("--impl", default="mujoco,pinocchio,drake")
    parser.add_argument("--states", type=int, default=10)
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    found = models(args.paths)
    if not found:
        print(f"error: paths: no {' or '.join(SUFFIXES)} file in {args.paths}", file=sys.stderr)
        return 2
    table = pd.concat([causes(p, impls=tuple(args.impl.split(",")), states=args.states)
                       for p in found], ignore_index=True)
    counts = table.groupby("standing").size().rename("rows").reset_index()
    suspected = table[table["standing"].isin((Standing.SUSPECTED.value, CRASHED))]
    text = (f"# Causes re-proved: {len(found)} models\n\n"
            + markdown_table(counts) + "\n\n## Suspected (fix not measured), and crashes\n\n"
            + (markdown_table(suspected.drop(columns="standing")) if len(suspected)
               else "none") + "\n")
    if args.out:
        write_atomic(args.out, text)
    print(text)
    return 1 if len(suspected) else 0


if __name__ == "__main__":
    sys.exit(main())

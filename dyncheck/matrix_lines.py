"""The parts of a version matrix's page that both matrices write (the book's cases,
:mod:`dyncheck.versions`; the user's models, :mod:`dyncheck.model_versions`): what the
matrix cost, each reproducer's outcome per release, the defects a step fixed or brought
back."""

from __future__ import annotations

from typing import Protocol

import pandas as pd

from dyncheck.environments import Footprint, Installer


def reproducer_lines(outcomes: dict[str, dict[str, str]]) -> list[str]:
    """A table of each reproducer's outcome under each release (release → name → outcome;
    none where the engine has no reproducer or no release ran one)."""
    if not any(outcomes.values()):
        return []
    table = pd.DataFrame(outcomes).rename_axis("reproducer").reset_index().fillna("not run")
    return ["#### The engine's defect reproducers under each release", "",
            "A reproducer exits 1 while its defect stands (`dyncheck explain NAME --reproducer "
            "FILE`); `does not run`: the script fails by itself under that release (an API it "
            "calls is missing).", "", table.to_markdown(index=False), ""]


class Stepped(Protocol):
    """Two consecutive releases and the defects fixed and back between them (read-only: a
    frozen :class:`Step` or :class:`~dyncheck.model_versions.ModelStep`)."""

    @property
    def old(self) -> str: ...
    @property
    def new(self) -> str: ...
    @property
    def fixed(self) -> tuple[str, ...]: ...
    @property
    def back(self) -> tuple[str, ...]: ...


def environment_lines(seconds: float | None, footprint: Footprint | None) -> list[str]:
    """What the matrix cost on this machine: its time, the disk its environments hold
    (:class:`~dyncheck.environments.Footprint`), each one's size, what it adds, its making."""
    lines = []
    if seconds is not None:
        took = f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.1f} min"
        lines += [f"This page took {took} on this machine, making the environments not made "
                  "before included.", ""]
    if footprint is not None and footprint.made:
        made = footprint.made
        copies = sum(m.apparent for m in made.values())
        shared = any(m.by is Installer.UV for m in made.values())
        lines += ["The environments (made once, reused; `dyncheck versions "
                  f"--remove-environments` deletes them) hold {_size(footprint.disk)} on disk, "
                  f"each file once however many of them link it (as copies: {_size(copies)})"
                  + (f"; uv's cache, shared by every release environment, holds "
                     f"{_size(footprint.cache)} more" if shared else "") + ":", ""]
        lines += [f"- {e} {r}: {_size(m.apparent)}, {_size(m.own)} of its own, made by "
                  f"{m.by.value}" + (f" in {m.seconds:.0f} s" if m.seconds is not None else "")
                  for (e, r), m in made.items()]
        lines += [""]
    return lines


def _size(size: int) -> str:
    return f"{size / 2**30:.2f} GiB" if size >= 2**30 else f"{size / 2**20:.0f} MiB"


def defect_lines(step: Stepped) -> list[str]:
    """The engine defects a step fixed or brought back, each by its catalogue name (its
    reproducer: ``dyncheck explain NAME --reproducer FILE``)."""
    lines = []
    for names, said, before, after in ((step.fixed, "Fixed", "fails", "passes"),
                                       (step.back, "Back", "passes", "fails")):
        if names:
            lines += [f"**{said} in {step.new}**: " + ", ".join(f"`{n}`" for n in names)
                      + f" (its reproducer {before} under {step.old} and {after} under "
                      f"{step.new}).", ""]
    return lines

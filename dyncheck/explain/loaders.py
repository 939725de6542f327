"""The loaders the catalogue's demonstrations share: Pinocchio's MJCF loader, and a model
loaded by MuJoCo's and another engine's check loaders side by side, with sampled states."""

from __future__ import annotations

from typing import Any


def pin_mjcf(xml: str):
    from dyncheck.adapters.pinocchio.api import parse_xml

    return parse_xml(xml)


def beside_mujoco(mjcf: str, other: Any, states: int) -> tuple[Any, Any, Any, Any]:
    """An MJCF written here loaded by MuJoCo's and another engine's check loader (``other``,
    a class of :mod:`dyncheck.adapters`), the canonical layout (MuJoCo's) and ``states``
    sampled states: (mujoco, other, canonical, states)."""
    import tempfile
    from pathlib import Path

    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.model_tree import canonical
    from dyncheck.adapters.mujoco.model import MujocoModel
    from dyncheck.check.sampling import sample

    with tempfile.TemporaryDirectory(prefix="dyncheck-explain-") as folder:
        path = Path(folder) / "model.xml"
        path.write_text(mjcf, encoding="utf-8")
        source = read(path)
        mine, theirs = MujocoModel(source), other(source)
    canon = canonical(mine.tree)
    return mine, theirs, canon, sample(canon, mine.tree, states, 0)

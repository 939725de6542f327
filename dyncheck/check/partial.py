"""Partial agreement: an engine that read only part of the model (Pinocchio's MJCF parser
reads only the first body under ``<worldbody>``) is compared on the part it did read.

Subtrees that hang from the world independently are independent blocks of the dynamics: M is
block-diagonal over them and h, forward and inverse dynamics of one block depend on that
block's coordinates alone (§2.2: the Lagrangian (2.2.23) is a sum over the subtrees, each
term in its own coordinates). So where the joints an engine holds are whole subtrees of the
canonical engine's tree, and it holds no joint the canonical engine lacks, its M, h, forward
and inverse dynamics are compared with the others' restricted to those coordinates. The
energies are sums over every body, the dropped ones included: not compared for such a pair.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from dyncheck.adapters.model_tree import NQ, NV, Dynamics, ModelTree
from dyncheck.referee.states import States


@dataclass(frozen=True, kw_only=True)
class Part:
    """The joints an engine holds, as a tree of their own (each joint's layout placed in the
    part's q and v), and where their coordinates sit in the canonical q and v."""

    tree: ModelTree
    q: np.ndarray
    v: np.ndarray
    dropped: tuple[str, ...]


def common_part(canonical: ModelTree, tree: ModelTree) -> Part | None:
    """``tree``'s joints as whole subtrees of ``canonical``'s, or None where they are not
    (a joint the canonical engine lacks, a type that differs, or a kept joint whose parent
    was dropped)."""
    held = {j.name: j for j in tree.joints}
    known = {j.name for j in canonical.joints}
    if set(held) - known or not held:
        return None
    q: list[int] = []
    v: list[int] = []
    kept, dropped = [], []
    q_at = v_at = 0
    for j in canonical.joints:
        if j.name in held:
            if held[j.name].type is not j.type or (j.parent is not None
                                                   and j.parent not in held):
                return None
            # its place in the part's own q and v (a reading of the part is laid out there)
            kept.append(replace(j, layout=replace(j.layout, q_start=len(q), v_start=len(v))))
            q.extend(range(q_at, q_at + NQ[j.type]))
            v.extend(range(v_at, v_at + NV[j.type]))
        else:
            dropped.append(j.name)
        q_at, v_at = q_at + NQ[j.type], v_at + NV[j.type]
    return Part(tree=replace(canonical, joints=tuple(kept), nq=len(q), nv=len(v)),
                q=np.array(q, int), v=np.array(v, int), dropped=tuple(dropped))


def states(batch: States, part: Part) -> States:
    return States(q=batch.q[:, part.q], v=batch.v[:, part.v], a=batch.a[:, part.v])


def restrict(dyn: Dynamics, columns: np.ndarray) -> Dynamics:
    """``dyn`` on the coordinates ``columns`` (positions in its own v); energies NaN (they
    are sums over every body)."""
    nan = np.full(len(dyn.kinetic), np.nan)
    return Dynamics(
        mass_matrix=dyn.mass_matrix[:, columns][:, :, columns], bias=dyn.bias[:, columns],
        forward=dyn.forward[:, columns], inverse=dyn.inverse[:, columns], kinetic=nan,
        potential=nan, unavailable=dyn.unavailable,
    )


def columns(mine: np.ndarray | None, common: np.ndarray) -> np.ndarray:
    """Where the canonical coordinates ``common`` sit in a result held on ``mine`` (None:
    the whole canonical v)."""
    if mine is None:
        return common
    return np.searchsorted(mine, common)

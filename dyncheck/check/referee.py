"""The book's general method (:mod:`dyncheck.reference.tree`) as one more implementation,
``reference``, on the neutral tree one engine read from the file (the report names which)."""

from __future__ import annotations

import numpy as np

from dyncheck.adapters.model_tree import Dynamics, ModelTree
from dyncheck.reference.tree import Body, TreeDynamics

ENGINE = "reference"


def bodies(tree: ModelTree) -> list[Body]:
    index = {j.name: i for i, j in enumerate(tree.joints)}
    return [
        Body(
            kind=str(j.type), parent=-1 if j.parent is None else index[j.parent],
            axis=j.axis, anchor=j.anchor, frame=j.frame, zero=j.layout.zero, mass=j.mass,
            com=j.com, inertia=j.inertia, armature=j.armature,
        )
        for j in tree.joints
    ]


class ReferenceModel:
    """The referee, in the canonical layout of ``tree`` (whose order it keeps)."""

    engine = ENGINE

    def __init__(self, tree: ModelTree) -> None:
        self.tree = tree
        self.solver = TreeDynamics(bodies(tree), tree.gravity)

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        n, nv = len(q), self.solver.nv
        mass = np.empty((n, nv, nv))
        bias, forward, inverse = (np.empty((n, nv)) for _ in range(3))
        kinetic, potential = np.empty(n), np.empty(n)
        with np.errstate(all="ignore"):  # an overflow shows as a non-finite result: a row
            for i in range(n):
                mass[i], bias[i], kinetic[i], potential[i] = self.solver.at(q[i], v[i])
                try:
                    forward[i] = np.linalg.solve(mass[i], -bias[i])
                except np.linalg.LinAlgError:  # M singular (a joint moving no mass, a NaN):
                    forward[i] = np.nan  # no forward dynamics — a failed row (non-finite)
                inverse[i] = mass[i] @ a[i] + bias[i]
        return Dynamics(
            mass_matrix=mass, bias=bias, forward=forward, inverse=inverse,
            kinetic=kinetic, potential=potential,
        )

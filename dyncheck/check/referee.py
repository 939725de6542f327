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
        """Every state at once (:meth:`TreeDynamics.at_states`); forward dynamics by one
        batched solve, a singular M (a joint moving no mass, a NaN) giving NaN for its state:
        a failed row (non-finite), never a crash."""
        with np.errstate(all="ignore"):  # an overflow shows as a non-finite result: a row
            mass, bias, kinetic, potential = self.solver.at_states(q, v)
            forward = np.full_like(bias, np.nan)
            try:
                forward = np.linalg.solve(mass, -bias[..., None])[..., 0]
            except np.linalg.LinAlgError:  # one singular M fails the batch: state by state
                for i in range(len(q)):
                    try:
                        forward[i] = np.linalg.solve(mass[i], -bias[i])
                    except np.linalg.LinAlgError:
                        pass
            inverse = np.einsum("sij,sj->si", mass, a) + bias
        return Dynamics(
            mass_matrix=mass, bias=bias, forward=forward, inverse=inverse,
            kinetic=kinetic, potential=potential,
        )

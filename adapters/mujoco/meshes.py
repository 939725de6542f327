"""How MuJoCo holds a model's meshes, for comparing the inertia other parsers take from the
same files: vertices rounded to float32 where the file writes them as text."""

from __future__ import annotations

import mujoco
import numpy as np

FLOAT32_EPS = float(np.finfo(np.float32).eps)


TEXT_MESHES = (".obj",)
"""Mesh files whose vertices are written as decimal text: MuJoCo rounds them to float32, a
parser reading doubles does not (binary STL and MSH hold float32 for every parser)."""


def mesh_rounding(m: mujoco.MjModel, from_geoms: frozenset[int],
                   text: frozenset[int]) -> dict[int, float]:
    """Body → the relative error its mesh-derived mass may carry from MuJoCo holding mesh
    vertices in float32 (the file's digits rounded, |δx| ≤ ε₃₂/2 · |x| per coordinate): a
    closed surface of area A moved by |δx| changes its volume V by at most A |δx|, so
    δV/V ≤ (√3/2) ε₃₂ r A / V, r the mesh's largest vertex distance in the file's frame.
    Only bodies that take their inertia from their geoms (``from_geoms``), and meshes read
    from text (``text``: mesh ids)."""
    out: dict[int, float] = {}
    for g in np.flatnonzero(m.geom_type == mujoco.mjtGeom.mjGEOM_MESH):
        k = int(m.geom_dataid[g])
        if k < 0 or k not in text or int(m.geom_bodyid[g]) not in from_geoms:
            continue
        verts = m.mesh_vert[m.mesh_vertadr[k] : m.mesh_vertadr[k] + m.mesh_vertnum[k]]
        faces = m.mesh_face[m.mesh_faceadr[k] : m.mesh_faceadr[k] + m.mesh_facenum[k]]
        a, b, c = (verts[faces[:, i]].astype(float) for i in range(3))
        normal = np.cross(b - a, c - a)
        area = 0.5 * float(np.linalg.norm(normal, axis=1).sum())
        volume = abs(float(np.einsum("ij,ij->", a, np.cross(b, c)))) / 6
        if volume <= 0:
            continue
        reach = float(np.abs(verts).max()) * np.sqrt(3) + float(np.linalg.norm(m.mesh_pos[k]))
        bound = np.sqrt(3) / 2 * FLOAT32_EPS * reach * area / volume
        body = int(m.geom_bodyid[g])
        out[body] = max(out.get(body, 0.0), bound)
    return out

"""Groups that walk together: the group force of Moussaïd et al. (2010) added to the crowd model.

M. Moussaïd, N. Perozo, S. Garnier, D. Helbing and G. Theraulaz, "The walking behaviour of pedestrian
social groups and its impact on crowd dynamics", PLoS ONE 5(4): e10047 (2010). A member ``i`` of a
group of ``N >= 2`` feels, besides the social force model's terms (:mod:`worldgen.people.crowd`),

    f_i^group = f_i^vis + f_i^att + f_i^rep

- gaze ``f^vis = -beta1 alpha_i v_i``: ``alpha_i`` is how far the head must turn beyond the vision field
  (``phi`` either side of the walking direction) to see the group's centre of mass; it brakes whoever
  walks ahead of the group;
- attraction ``f^att = q_A beta2 U_i``: ``U_i`` the unit vector to the centre of mass, ``q_A = 1`` when
  farther from it than ``(N - 1) / 2`` m, else 0;
- repulsion ``f^rep = sum_k q_R beta3 W_ik``: ``W_ik`` the unit vector from member ``k`` to ``i``,
  ``q_R = 1`` when the two overlap (here: their discs, centres closer than two radii), else 0.

The values are the paper's (beta1 4, beta2 3, beta3 1, phi 90 degrees). Forces are per unit mass
(accelerations), as everywhere in the crowd model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["GroupForce", "group_force"]


@dataclass(frozen=True)
class GroupForce:
    """The group terms of Moussaïd, Perozo, Garnier, Helbing & Theraulaz, "The walking behaviour of
    pedestrian social groups and its impact on crowd dynamics", PLoS ONE 5(4): e10047 (2010), with the
    paper's values (docs/people.md): gaze ``-beta1 alpha v``, attraction ``beta2`` toward the group's
    centre beyond ``(N - 1) / 2`` m from it, repulsion ``beta3`` from each member whose disc overlaps."""

    beta1: float = 4.0  # gaze: braking per radian of head turn needed to see the group's centre, 1/s
    beta2: float = 3.0  # attraction toward the group's centre, m/s^2
    beta3: float = 1.0  # repulsion from an overlapping member, m/s^2
    phi: float = math.radians(90.0)  # half the vision field the centre must be in before the head turns, rad


def group_force(p: np.ndarray, v: np.ndarray, e: np.ndarray, groups: np.ndarray, radius: float,
                m: GroupForce = GroupForce()) -> np.ndarray:
    """(n, 2) Moussaïd et al.'s (2010) group force on each member of a group of two or more (zero for
    the others): with ``c`` the group's centre (the mean of its members' positions) and ``N`` its size,

    - gaze ``-beta1 alpha v``: ``alpha`` is how far (rad) the head must turn beyond ``phi`` from the
      walking direction (the velocity, else ``e`` from rest) to see ``c``; it slows one who walks ahead;
    - attraction ``beta2`` toward ``c`` when farther from it than ``(N - 1) / 2`` m;
    - repulsion ``beta3`` away from each other member whose disc overlaps (centres closer than ``2 radius``).
    """
    n = len(p)
    out = np.zeros((n, 2))
    g = np.asarray(groups, dtype=np.int64)
    member = g >= 0
    if n < 2 or not member.any():
        return out
    size = np.bincount(g[member], minlength=int(g.max()) + 1).astype(float)
    cx = np.bincount(g[member], p[member, 0], minlength=len(size)) / np.maximum(size, 1)
    cy = np.bincount(g[member], p[member, 1], minlength=len(size)) / np.maximum(size, 1)
    idx = np.flatnonzero(member & (size[np.maximum(g, 0)] >= 2))
    if not len(idx):
        return out
    gi = g[idx]
    to = np.column_stack([cx[gi], cy[gi]]) - p[idx]
    dist = np.hypot(to[:, 0], to[:, 1])
    speed = np.hypot(v[idx, 0], v[idx, 1])
    heading = np.where(speed[:, None] > 1e-9, v[idx] / np.maximum(speed, 1e-12)[:, None], e[idx])
    cos_t = np.einsum("ij,ij->i", heading, to) / np.maximum(dist, 1e-12)
    alpha = np.where(dist > 1e-9, np.maximum(np.arccos(np.clip(cos_t, -1.0, 1.0)) - m.phi, 0.0), 0.0)
    out[idx] -= m.beta1 * alpha[:, None] * v[idx]
    far = dist > (size[gi] - 1) / 2
    out[idx[far]] += m.beta2 * to[far] / dist[far, None]
    dx = p[idx, None, :] - p[None, idx, :]
    d = np.hypot(dx[..., 0], dx[..., 1])
    touch = (gi[:, None] == gi[None, :]) & (d < 2 * radius) & (d > 1e-12)
    w = np.where(touch, m.beta3 / np.maximum(d, 1e-12), 0.0)
    out[idx] += np.einsum("ij,ijk->ik", w, dx)
    return out

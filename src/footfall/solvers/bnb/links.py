"""Links between choice groups coupled by plain rows (``BnbSettings.links``).

Two groups coupled by a plain row (the heading rate, eq. 5.12e, between the segment groups of
consecutive steps) keep only the member pairs that row allows on the members' boxes; the group
weights must be the marginals of weights on those pairs, written as prefix rows when the pairs
form a staircase (:func:`_staircase`), and children drop the members left without a partner
(:func:`_propagate`). Tighter but dearer per node, so off by default.
"""

from __future__ import annotations

import numpy as np

from footfall._typing import FloatArray
from footfall.solvers.bnb.model import _Link, _Structure
from footfall.solvers.settings import BnbSettings


def _staircase(
    s: _Structure, link: _Link
) -> tuple[list[tuple[int, int, int, int]], list[int]] | None:
    """The link's flow condition as prefix rows, when the compatible pairs form a staircase; None
    otherwise.

    Staircase: in member order, each member of either group is compatible with a contiguous run
    of the other group's members, and the runs move forward with the member (heading segments of
    consecutive steps under the heading rate, eq. 5.12e). Weights ``z1``, ``z2`` (each summing to
    1) are then the marginals of weights on the compatible pairs exactly when every prefix of one
    group fits into the members its prefix reaches: ``sum_{a <= k} z1_a <= sum_{b <= hi1(k)} z2_b``
    and the same with the groups swapped (an interval of members splits into a prefix and a suffix,
    and a suffix condition is the other group's prefix condition).

    Returns:
        Rows ``(g, k, g', k')``: prefix ``k`` of group ``g`` <= prefix ``k'`` of group ``g'``
        (prefix ``k``: the sum of the first ``k + 1`` members' binaries), and the binaries of the
        members with no compatible partner (fixed to 0).
    """
    mem = [s.groups[g].members for g in link.groups]
    pos = [{z: k for k, z in enumerate(m)} for m in mem]
    adj = np.zeros((len(mem[0]), len(mem[1])), dtype=bool)
    for z1, z2 in link.pairs:
        adj[pos[0][int(z1)], pos[1][int(z2)]] = True
    rows: list[tuple[int, int, int, int]] = []
    zero: list[int] = []
    for side, a_mat in ((0, adj), (1, adj.T)):
        prev_lo, prev_hi = -1, -1
        reach = -1  # furthest partner of the prefix so far
        for k in range(a_mat.shape[0]):
            hits = np.flatnonzero(a_mat[k])
            if not len(hits):
                zero.append(mem[side][k])
                continue
            lo, hi = int(hits[0]), int(hits[-1])
            if hi - lo + 1 != len(hits) or lo < prev_lo or hi < prev_hi:
                return None
            prev_lo, prev_hi = lo, hi
            reach = max(reach, hi)
            if reach < len(mem[1 - side]) - 1:
                rows.append((link.groups[side], k, link.groups[1 - side], reach))
    return rows, zero


def _member_box(s: _Structure, g: int, z: int) -> tuple[FloatArray, FloatArray]:
    """Bounds of the group's variables when ``z = 1``: the variable bounds tightened by the
    member's single-variable rows (lower, upper), each (|V|,)."""
    grp = s.groups[g]
    lo = s.problem.lb[grp.variables].copy()
    hi = s.problem.ub[grp.variables].copy()
    mb = s.member[z]
    nnz = np.count_nonzero(mb.a_v, axis=1)
    for j in np.flatnonzero(nnz == 1):
        c = int(np.flatnonzero(mb.a_v[j])[0])
        v = float(mb.a_v[j, c])
        if v > 0:
            hi[c] = min(hi[c], mb.beta[j] / v)
        else:
            lo[c] = max(lo[c], mb.beta[j] / v)
    return lo, hi


def _links(s: _Structure, settings: BnbSettings) -> list[_Link]:
    """Member pairs of two groups that the plain rows between them allow.

    A plain row whose variables all lie in the variables of two groups ``g1 != g2`` (e.g. the
    heading rate of eq. 5.12e between the segment groups of consecutive steps) couples them: the
    pair ``(z1, z2)`` is incompatible when the row's smallest activity over the box that ``z1``
    and ``z2`` imply exceeds its right-hand side. The relaxation then requires the weights of the
    two groups to be the marginals of weights on the compatible pairs (a transportation flow),
    which every integral point satisfies with one pair at weight 1.
    """
    pr = s.problem
    a = s.plain_le.tocsr()
    in_groups: dict[int, set[int]] = {}
    for g, grp in enumerate(s.groups):
        if len(grp.members) < 2:
            continue
        for c in grp.variables:
            in_groups.setdefault(int(c), set()).add(g)
    rows_of: dict[tuple[int, int], list[int]] = {}
    for r in range(a.shape[0]):
        cols = a.indices[a.indptr[r] : a.indptr[r + 1]]
        if len(cols) < 2:
            continue
        cover = [in_groups.get(int(c), set()) for c in cols]
        if any(not cv for cv in cover):
            continue
        for g1 in cover[0] | cover[1]:
            for g2 in cover[0] | cover[1]:
                if g1 < g2 and all(g1 in cv or g2 in cv for cv in cover):
                    rows_of.setdefault((g1, g2), []).append(r)
    links = []
    for (g1, g2), rows in sorted(rows_of.items()):
        v1, v2 = s.groups[g1].variables, s.groups[g2].variables
        cols = np.union1d(v1, v2)
        pos1, pos2 = np.searchsorted(cols, v1), np.searchsorted(cols, v2)
        sub = a[rows][:, cols].toarray()
        rhs = s.plain_b[rows]
        boxes2 = [_member_box(s, g2, z2) for z2 in s.groups[g2].members]
        pairs = []
        for z1 in s.groups[g1].members:
            lo1, hi1 = _member_box(s, g1, z1)
            for z2, (lo2, hi2) in zip(s.groups[g2].members, boxes2, strict=True):
                lo, hi = pr.lb[cols].copy(), pr.ub[cols].copy()
                lo[pos1], hi[pos1] = np.maximum(lo[pos1], lo1), np.minimum(hi[pos1], hi1)
                lo[pos2], hi[pos2] = np.maximum(lo[pos2], lo2), np.minimum(hi[pos2], hi2)
                low = np.sum(np.minimum(sub * lo, sub * hi), axis=1)
                tol = settings.feas_tol
                if np.all(lo <= hi + tol) and np.all(
                    low <= rhs + tol * np.maximum(1.0, np.abs(rhs))
                ):
                    pairs.append((z1, z2))
        n_all = len(s.groups[g1].members) * len(s.groups[g2].members)
        if len(pairs) <= (1.0 - settings.link_min_drop) * n_all:
            links.append(_Link((g1, g2), np.array(pairs, dtype=np.int64).reshape(-1, 2)))
    return links


def _propagate(
    s: _Structure, allowed: tuple[tuple[int, ...], ...]
) -> tuple[tuple[int, ...], ...] | None:
    """Drop the members without a compatible allowed partner in some linked group (see
    :func:`_links`), until nothing changes; None when a group is left without members (no
    integral point of the node exists). Removes only members that no feasible point uses."""
    cur = [set(m) for m in allowed]
    changed = True
    while changed:
        changed = False
        for link in s.compat:
            g1, g2 = link.groups
            keep1 = {int(a) for a, b in link.pairs if a in cur[g1] and b in cur[g2]}
            keep2 = {int(b) for a, b in link.pairs if a in cur[g1] and b in cur[g2]}
            if keep1 != cur[g1] or keep2 != cur[g2]:
                cur[g1], cur[g2] = keep1, keep2
                changed = True
                if not keep1:
                    return None
    return tuple(m if len(m) == len(c) else tuple(z for z in m if z in c)
                 for m, c in zip(allowed, cur, strict=True))  # fmt: skip

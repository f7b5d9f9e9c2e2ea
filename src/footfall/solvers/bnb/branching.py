"""Node bookkeeping, integrality by geometry, SOS1 branching and the dive.

A relaxation point that satisfies the rows of one member of every group is a feasible point of
the MIQCQP (:func:`_choice`, :func:`_finish`), even when the interior-point weights are spread.
Otherwise the group whose nearest member is violated most is split where the cumulative weight of
its members (in index order, the angle order for segments) crosses 1/2 (:func:`_branch`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.solvers.bnb.links import _propagate
from footfall.solvers.bnb.model import _Structure
from footfall.solvers.bnb.relaxation import HullRelaxation


@dataclass(order=True)
class _Node:
    bound: float
    order: int
    allowed: tuple[tuple[int, ...], ...] = field(compare=False)
    x: FloatArray | None = field(compare=False, default=None)
    depth: int = field(compare=False, default=0)
    full: bool = field(compare=False, default=False)


def _weights(x: FloatArray, mem: tuple[int, ...]) -> FloatArray:
    return np.clip(x[list(mem)], 0.0, 1.0)


def _violations(s: _Structure, x: FloatArray, g: int, mem: tuple[int, ...]) -> FloatArray:
    """Largest violation of each member's indicator rows at ``x``, shape (len(mem),) (0 for a
    member without rows)."""
    if g not in s.stacked:
        members = s.groups[g].members
        a = np.vstack([s.member[z].a_v for z in members])
        beta = np.concatenate([s.member[z].beta for z in members])
        owner = np.repeat(np.arange(len(members)), [len(s.member[z].beta) for z in members])
        s.stacked[g] = (a, beta, owner, {z: k for k, z in enumerate(members)})
    a, beta, owner, pos = s.stacked[g]
    worst = np.full(len(pos), -np.inf)
    np.maximum.at(worst, owner, a @ x[s.groups[g].variables] - beta)
    out = worst[[pos[z] for z in mem]]
    out[np.isneginf(out)] = 0.0
    return out


def _choice(
    s: _Structure, x: FloatArray, allowed: tuple[tuple[int, ...], ...], tol: float
) -> tuple[tuple[int, ...], ...] | None:
    """A member per group whose rows ``x`` satisfies within ``tol`` (None if some group has none).

    ``x`` then is a feasible point of the MIQCQP with those binaries set to 1: the relaxation solution
    is integer feasible even when the IPM spread the weights over several equally good members.
    """
    out = []
    for g, mem in enumerate(allowed):
        if len(mem) == 1:
            out.append(mem)
            continue
        v = _violations(s, x, g, mem)
        k = int(np.argmin(v))
        if v[k] > tol:
            return None
        out.append((mem[k],))
    return tuple(out)


def _without(allowed: tuple[tuple[int, ...], ...], drop: set[int]) -> tuple[tuple[int, ...], ...]:
    """``allowed`` without the members ``drop``; a group with one member keeps it."""
    return tuple(
        mem if len(mem) == 1 else tuple(z for z in mem if z not in drop) for mem in allowed
    )


def _sos_point(w: FloatArray) -> int:
    """Where an SOS split of weights ``w`` (members in index order) cuts: at the weighted mean."""
    centre = float(np.dot(w, np.arange(len(w)))) / max(float(np.sum(w)), 1e-12)
    return min(max(round(centre + 0.5), 1), len(w) - 1)


def _candidates(
    s: _Structure, x: FloatArray, allowed: tuple[tuple[int, ...], ...], tol: float
) -> list[int]:
    """Groups with every member violated at ``x`` (beyond ``tol``), the one whose nearest member
    is violated most first."""
    scored: list[tuple[float, int]] = []
    for g, mem in enumerate(allowed):
        if len(mem) < 2:
            continue
        viol = _violations(s, x, g, mem)
        if float(np.min(viol)) <= tol:
            continue
        scored.append((-float(np.min(viol)), g))
    scored.sort()
    return [g for _, g in scored]


def _split(
    x: FloatArray, allowed: tuple[tuple[int, ...], ...], g: int
) -> tuple[tuple[tuple[int, ...], ...], tuple[tuple[int, ...], ...]]:
    """Split group ``g`` into two halves at the weighted mean of its members (SOS1 branching)."""
    mem = allowed[g]
    k = _sos_point(_weights(x, mem))
    one, other = mem[:k], mem[k:]
    left = [*allowed]
    right = [*allowed]
    left[g] = one
    right[g] = other
    return tuple(left), tuple(right)


def _branch(
    s: _Structure, x: FloatArray, allowed: tuple[tuple[int, ...], ...], tol: float
) -> tuple[tuple[tuple[int, ...], ...], ...] | None:
    """Split the best violated group (see :func:`_candidates`) into two halves (:func:`_split`);
    with links, each child is reduced by :func:`_propagate` (a child left empty is dropped)."""
    cands = _candidates(s, x, allowed, tol)
    if not cands:
        return None
    children = _split(x, allowed, cands[0])
    if not s.compat:
        return children
    return tuple(c for c in (_propagate(s, a) for a in children) if c is not None)


def _finish(s: _Structure, x: FloatArray, chosen: tuple[tuple[int, ...], ...]) -> FloatArray:
    """A relaxation solution as a MIQCQP point: the chosen binaries set to 1, the others to 0, and
    each group's private variables recovered from the chosen member's rows."""
    pr = s.problem
    out = x.copy()
    # Variables fixed by their bounds take exactly that value (the node solver returns them only
    # to its tolerance, e.g. -3e-18 for a 0).
    fixed = pr.lb == pr.ub
    out[fixed] = pr.lb[fixed]
    out[pr.integer] = 0.0
    for g, mem in enumerate(chosen):
        z = mem[0]
        out[z] = 1.0
        for v in s.groups[g].private:
            lo, hi = float(pr.lb[v]), float(pr.ub[v])
            for cc, vv, bb in s.member[z].orig:
                hit = cc == v
                if not np.any(hit):
                    continue
                a = float(vv[hit][0])
                rest = float(vv[~hit] @ out[cc[~hit]])
                if a > 0.0:
                    hi = min(hi, (bb - rest) / a)
                else:
                    lo = max(lo, (bb - rest) / a)
            out[v] = 0.5 * (lo + hi) if lo <= hi else lo
    return out


def _root_allowed(s: _Structure) -> tuple[tuple[int, ...], ...]:
    """Members allowed by the binaries' own bounds (a binary fixed to 1 excludes the others)."""
    pr = s.problem
    out = []
    for grp in s.groups:
        ones = tuple(z for z in grp.members if pr.lb[z] >= 0.5)
        out.append(ones if ones else tuple(z for z in grp.members if pr.ub[z] >= 0.5))
    return tuple(out)


def _dive(
    relax: HullRelaxation,
    x: FloatArray,
    allowed: tuple[tuple[int, ...], ...],
    cutoff: float,
    deadline: float,
    stop: Any = None,
) -> tuple[tuple[int, ...], ...] | None:
    """Depth-first dive from a relaxation solution: fix the group whose nearest member (least
    violated rows) is nearest to that member and re-solve, until the relaxation point satisfies
    one member per group (returns that assignment) or is hopeless (None): infeasible, or its bound
    reaches ``cutoff``. Gives up at ``deadline`` or when the shared flag ``stop`` is set."""
    s = relax.s
    cur = allowed
    for _ in range(2 * len(cur)):
        if time.perf_counter() > deadline or (stop is not None and stop.value):
            return None
        best_g, best_v, z = -1, math.inf, -1
        for g, mem in enumerate(cur):
            if len(mem) > 1:
                viol = _violations(s, x, g, mem)
                k = int(np.argmin(viol))
                if viol[k] < best_v:
                    best_g, best_v, z = g, float(viol[k]), mem[k]
        if best_g < 0:
            return None
        mem = cur[best_g]
        fixed = list(cur)
        fixed[best_g] = (z,)
        res = relax.solve(tuple(fixed))
        if res.status != "solved" or res.x is None:
            rest = list(cur)
            rest[best_g] = tuple(m for m in mem if m != z)
            cur = tuple(rest)
            res = relax.solve(cur)
            if res.status != "solved" or res.x is None:
                return None
        else:
            cur = tuple(fixed)
        if res.bound >= cutoff:
            return None
        x = res.x
        chosen = _choice(s, x, cur, relax.settings.row_tol)
        if chosen is not None:
            return chosen
    return None

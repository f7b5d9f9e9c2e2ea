"""The data of a problem's structure (see :mod:`footfall.solvers.bnb`): its choice groups, their
members' indicator rows and the links between groups. :mod:`.structure` builds it, :mod:`.links`
couples its groups, the relaxation and the search read it."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from footfall._typing import FloatArray, IntArray
from footfall.solvers.problem import MIQCQP


@dataclass(frozen=True)
class _Link:
    """Two choice groups coupled by plain rows, and the member pairs those rows allow.

    Attributes:
        groups: the two group indices ``(g1, g2)``.
        pairs: binaries ``(z1, z2)`` of the compatible member pairs, (P, 2); a pair is dropped only
            when the plain rows between the groups cannot hold on the box both members imply.
    """

    groups: tuple[int, int]
    pairs: IntArray


@dataclass(frozen=True)
class _Member:
    """Indicator rows of one binary: ``a^T x <= beta`` when the binary is 1.

    Attributes:
        var: the binary's index.
        a_v: rows over the group's variables ``V`` (private variables eliminated), (m, |V|).
        a_f: the same rows over the group's forms ``f = B x_V``, (m, k).
        beta: right-hand sides, (m,).
        orig: the original rows ``(columns, coefficients, rhs)``, to recover private variables.
    """

    var: int
    a_v: FloatArray
    a_f: FloatArray
    beta: FloatArray
    orig: tuple[tuple[IntArray, FloatArray, float], ...]


@dataclass(frozen=True)
class _Group:
    """A choice group ``sum_{z in members} z = 1``.

    Attributes:
        members: binary variable indices, ascending.
        variables: ``V``, the continuous variables of the members' rows (private ones removed).
        basis: ``B`` (k, |V|), orthonormal basis of the row space of every member row over ``V``;
            the relaxation copies the k forms ``B x_V`` instead of ``x_V``.
        f_lb, f_ub: bounds of the forms over the variable bounds, (k,).
        private: variables that appear in this group's rows and nowhere else but their bounds;
            they are eliminated (Fourier-Motzkin) and recovered from the chosen member.
        cost_rows: objective rows ``w (F x - t)^2`` that lie in the span of the group's forms
            (e.g. the horizontal step-length terms of eq. 5.11 in a heading-segment group); the
            relaxation charges them in perspective form (see :class:`HullRelaxation`).
        cost_v, cost_f: those rows over ``V`` (m, |V|) and over the forms (m, k).
        cost_t, cost_w: their targets and weights, (m,).
    """

    members: tuple[int, ...]
    variables: IntArray
    basis: FloatArray
    f_lb: FloatArray
    f_ub: FloatArray
    private: IntArray
    cost_rows: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    cost_v: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    cost_f: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    cost_t: FloatArray = field(default_factory=lambda: np.zeros(0))
    cost_w: FloatArray = field(default_factory=lambda: np.zeros(0))


@dataclass
class _Structure:
    """The problem split into its static convex part and its choice groups."""

    problem: MIQCQP
    groups: list[_Group]
    member: dict[int, _Member]
    group_of: dict[int, int]
    plain_le: sp.csr_matrix
    plain_b: FloatArray
    assigned: NDArray[np.bool_]  # cost rows charged in perspective form by a group
    #: compatible member pairs of groups linked by plain rows (see :func:`_links`)
    links: list[_Link] = field(default_factory=list)
    #: every link (also those written as prefix rows), for :func:`_propagate`
    compat: list[_Link] = field(default_factory=list)
    #: staircase links as prefix rows ``(g, k, g', k')`` (see :func:`_staircase`)
    prefix_rows: list[tuple[int, int, int, int]] = field(default_factory=list)
    #: per group, its members' rows stacked (see :func:`_violations`), built on first use
    stacked: dict[int, tuple[FloatArray, FloatArray, IntArray, dict[int, int]]] = field(
        default_factory=dict
    )

"""The short-horizon footstep MIQP written out as a :class:`MIQCQP`, for any backend.

:class:`footfall.planning.horizon.HorizonPlanner` solves its problem by a condensed search of its
own (daqp at every node). :func:`horizon_problem` writes the same problem independently of that
search (document 000, eq. 5.11-5.18 over H footsteps), so that SCIP or Gurobi can check the
search's answers (``footfall bench plan --horizon``, the tests).
"""

from __future__ import annotations

import math

import numpy as np

from footfall._geometry import rot2
from footfall.planning.horizon import TORQUE_SIDES, HorizonInput, HorizonPlanner
from footfall.solvers.problem import MIQCQP, ProblemBuilder


def horizon_problem(planner: HorizonPlanner, inp: HorizonInput) -> MIQCQP:
    """The problem of ``planner.solve(inp)`` as a :class:`MIQCQP` for any backend.

    Written independently of the condensed search: ALIP states at every block boundary are
    variables with the dynamics (5.12a) and resets (5.12b) as equality rows, the octagon as
    ``TORQUE_SIDES`` rows per block, each region choice as a binary with big-M plane and polygon
    rows (5.12i). Every footstep's region set is the scene's whole terrain, not the candidates.
    Variable order: ``u`` (H, K - 1, 2), ``p`` (H, 3), ``x`` (H, K, 4) (node k of step j, before
    the reset), ``x_final`` (4,), the region binaries (H, R).
    """
    planner.check_input(inp)
    rb, h, blocks = planner.robot, planner.h, planner.blocks
    w, opt = planner.options.weights, planner.options
    alip = rb.alip()
    b = ProblemBuilder()
    lim = opt.torque_limits
    u_abs = rb.u_max if lim is None else max(lim)
    u = b.add_vars("u", (h, blocks, 2), lb=-u_abs, ub=u_abs)
    lo_box, hi_box = planner.terrain.bounds()
    p = b.add_vars("p", (h, 3), lb=lo_box, ub=hi_box)
    x = b.add_vars("x", (h, blocks + 1, 4))
    x_final = b.add_vars("x_final", (4,))
    for k in range(4):
        b.add_eq({int(x[0, 0, k]): 1.0}, float(inp.alip_state[k]), f"5.12c x0[{k}]")
    a_r, b_r = alip.reset_map(rb.t_ds)
    p0 = inp.stance_foot
    for j in range(h):
        dt = inp.time_left / blocks if j == 0 else rb.node_dt
        ad, bd = alip.discretize(dt)
        for blk in range(blocks):
            for k in range(4):
                row = {int(x[j, blk + 1, k]): 1.0}
                for kk in range(4):
                    row[int(x[j, blk, kk])] = row.get(int(x[j, blk, kk]), 0.0) - ad[k, kk]
                for kk in range(2):
                    row[int(u[j, blk, kk])] = -bd[k, kk]
                b.add_eq(row, 0.0, f"5.12a step {j} block {blk}")
            for kk in range(2):
                b.add_square({int(u[j, blk, kk]): 1.0}, 0.0, w.torque * dt / rb.node_dt, "torque")
            for s in range(TORQUE_SIDES):
                phi = 2.0 * math.pi * s / TORQUE_SIDES
                if lim is None:
                    coef, rhs_u = (math.cos(phi), math.sin(phi)), rb.u_max
                else:  # in stance j's frame: (cos phi / U_x, sin phi / U_y) . R^T u
                    c, s_ = math.cos(float(inp.headings[j])), math.sin(float(inp.headings[j]))
                    nx, ny = math.cos(phi) / lim[0], math.sin(phi) / lim[1]
                    coef, rhs_u = (c * nx - s_ * ny, s_ * nx + c * ny), 1.0
                b.add_le(
                    {int(u[j, blk, 0]): coef[0], int(u[j, blk, 1]): coef[1]},
                    rhs_u * math.cos(math.pi / TORQUE_SIDES),
                    f"5.12d octagon step {j} block {blk}",
                )
        nxt = x[j + 1, 0] if j + 1 < h else x_final
        rhs = np.zeros(4)
        for k in range(4):
            row = {int(nxt[k]): 1.0}
            for kk in range(4):
                row[int(x[j, blocks, kk])] = -a_r[k, kk]
            for kk in range(3):
                row[int(p[j, kk])] = row.get(int(p[j, kk]), 0.0) - b_r[k, kk]
                if j == 0:
                    rhs[k] -= b_r[k, kk] * p0[kk]
                else:
                    row[int(p[j - 1, kk])] = row.get(int(p[j - 1, kk]), 0.0) + b_r[k, kk]
            b.add_eq(row, float(rhs[k]), f"5.12b reset {j}")
    q_x = w.terminal_diag(rb)
    for k in range(4):
        b.add_square(
            {int(x_final[k]): 1.0}, float(inp.state_ref[k]), w.terminal * float(q_x[k]), "terminal"
        )
    side = inp.stance
    for j in range(h):
        g_rows, h_rows = rb.reach.halfspaces(side)
        rot = rot2(float(inp.headings[j]))
        for r in range(len(h_rows)):
            a = rot @ g_rows[r]
            row = {int(p[j, 0]): float(a[0]), int(p[j, 1]): float(a[1])}
            rhs_r = float(h_rows[r])
            if j == 0:
                rhs_r += float(a @ p0[:2])
            else:
                row[int(p[j - 1, 0])] = -float(a[0])
                row[int(p[j - 1, 1])] = -float(a[1])
            b.add_le(row, rhs_r, f"5.12f reach {j}")
        dz = {int(p[j, 2]): 1.0}
        z_prev = 0.0
        if j == 0:
            z_prev = float(p0[2])
        else:
            dz[int(p[j - 1, 2])] = -1.0
        b.add_le(dz, z_prev + rb.step_height_max, f"step height {j}")
        b.add_le({k_: -v for k_, v in dz.items()}, -z_prev + rb.step_height_max, f"step height {j}")
        for k in range(3):
            prev = {} if j == 0 else {int(p[j - 1, k]): -1.0}
            target = float(p0[k]) if j == 0 else 0.0
            b.add_square(
                {int(p[j, k]): 1.0, **prev}, target, w.step * float(w.step_matrix[k]), "step"
            )
            b.add_square({int(p[j, k]): 1.0}, float(inp.footsteps_ref[j, k]), opt.track, "track")
        side = side.other
    terrain = list(planner.terrain)
    hreg = b.add_binaries("H", (h, len(terrain)))
    for j in range(h):
        b.add_eq({int(v): 1.0 for v in hreg[j]}, 1.0, f"5.12j one region {j}")
        pv = [int(p[j, k]) for k in range(3)]
        for r, region in enumerate(terrain):
            z = int(hreg[j, r])
            a_pl, b_pl = region.plane_rows()
            for row_a, row_b in zip(a_pl, b_pl, strict=True):
                b.add_le_big_m(
                    dict(zip(pv, map(float, row_a), strict=True)), float(row_b), z, "5.17"
                )
            a_poly, b_poly = region.halfspaces()
            for row_a, row_b in zip(a_poly, b_poly - opt.region_margin, strict=True):
                b.add_le_big_m(
                    dict(zip(pv[:2], map(float, row_a), strict=True)), float(row_b), z, "5.18"
                )
    return b.build()

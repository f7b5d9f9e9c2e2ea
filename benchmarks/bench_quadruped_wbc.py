"""Quadruped on the document's slopes, servo vs whole-body control: centre of pressure vs the
planned ZMP and speed, every controller on the same plan in one run (so the speed ratio shares the
machine's state).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_quadruped_wbc.py [--cycles 6]
"""

from __future__ import annotations

import argparse
import math

from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
from footfall.sim.quadruped.sim import simulate
from footfall.sim.quadruped.wbc import QuadrupedWbcGains


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cycles", type=int, default=6)
    args = ap.parse_args()
    print("slope/body  controller  QP every  x real time  ratio to servo  CoP-ZMP mean/max [cm]")
    for slope, body in ((15.0, 10.0), (20.0, 13.0)):
        params = GaitParams(
            slope=math.radians(slope), body_pitch=math.radians(body), cycles=args.cycles
        )
        plan = plan_gait(QuadrupedRobot(), params)
        servo_rtf = math.nan
        for ctrl, every in (("servo", 0), ("wbc", 1), ("wbc", 2), ("wbc", 4)):
            gains = QuadrupedWbcGains(qp_every=every) if ctrl == "wbc" else None
            res = simulate(plan, controller=ctrl, wbc_gains=gains)
            m = res.metrics
            rtf = res.trace.sim_time / res.trace.wall_time
            if ctrl == "servo":
                servo_rtf = rtf
            print(
                f"{slope:g}/{body:g}  {ctrl:>6}  {every or '-':>4}  {rtf:8.1f}  "
                f"{rtf / servo_rtf:8.2f}  {100 * m.zmp_error_mean_m:.2f} / "
                f"{100 * m.zmp_error_max_m:.2f}  fell={m.fell} qp_failures={res.trace.qp_failures}"
            )


if __name__ == "__main__":
    main()

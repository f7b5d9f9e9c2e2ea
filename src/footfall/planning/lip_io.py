"""JSON form of a :class:`LipWalk` (the ``lip_walk.json`` the CLI writes)."""

from __future__ import annotations

from typing import Any

from footfall.planning.lip_walk import LipWalk


def lip_walk_to_dict(walk: LipWalk, dt: float = 0.01) -> dict[str, Any]:
    """Plain-JSON dict: footsteps (actual and ideal), CoM samples and final state, SI units."""
    traj = walk.com_trajectory(dt)
    p = walk.params
    return {
        "units": {"position": "m", "velocity": "m/s", "time": "s", "angle": "rad"},
        "params": {
            "z_c": p.z_c,
            "t_sup": p.t_sup,
            "sx": list(p.sx),
            "sy": list(p.sy),
            "theta": list(p.headings),
            "a": p.a,
            "b": p.b,
            "a_stop": p.a_stop,
            "b_stop": p.b_stop,
            "com0": list(p.com0),
            "vel0": list(p.vel0),
            "foot0": list(p.foot0),
            "g": p.g,
        },
        "footsteps": [
            {
                "step": i,
                "actual": walk.footholds[i].tolist(),
                "ideal": walk.ideal_footholds[i].tolist(),
            }
            for i in range(walk.footholds.shape[0])
        ],
        "com": {k: traj[k].tolist() for k in ("t", "x", "y", "vx", "vy")},
        "final_state": {
            "x": float(walk.final_com[0]),
            "y": float(walk.final_com[1]),
            "vx": float(walk.final_vel[0]),
            "vy": float(walk.final_vel[1]),
        },
    }

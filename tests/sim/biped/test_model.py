"""MuJoCo biped (issue 7): the compiled model against its dataclass, terrain geoms vs region planes."""

from __future__ import annotations

import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall.control.adjusters import U_MAX_FOOT_SHARE  # noqa: E402
from footfall.errors import InputError  # noqa: E402
from footfall.models.biped import BipedParams, Side  # noqa: E402
from footfall.robots import names as nm  # noqa: E402
from footfall.sim.biped.model import (  # noqa: E402
    BipedModel,
    biped_mjcf,
    measure_model,
    planner_params,
)
from footfall.sim.biped.terrain_mjcf import terrain_xml  # noqa: E402
from footfall.terrain import Region, Terrain, builtin_scene, builtin_scene_names  # noqa: E402

#: masses are summed in double precision
MASS_TOL = 1e-9
#: the analytic nominal-posture CoM vs MuJoCo's forward kinematics [m]
COM_TOL = 1e-9
#: ray-cast surface heights vs the region planes [m]
HEIGHT_TOL = 1e-6
#: the mass of the two ankle-pitch hubs the MJCF adds (0.05 kg each)
HUB_MASS = 0.1
#: sample points per region
SAMPLES = 25


def _analytic_com(p: BipedModel) -> tuple[float, float]:
    """(x, z) of the CoM at the nominal posture from link geometry alone (sole at z = 0)."""
    hp, _, _ = p.leg_angles(p.nominal_hip_height)
    a = -hp  # thigh lean forward
    hip_z = p.nominal_hip_height
    knee = np.array([p.thigh_length * math.sin(a), hip_z - p.thigh_length * math.cos(a)])
    ankle = np.array([0.0, p.ankle_height])
    foot_h = 0.03  # the MJCF's foot box height
    parts = [
        (p.pelvis_mass, np.array([0.0, p.pelvis_height])),
        (p.torso_mass, np.array([0.0, p.pelvis_height + p.torso_offset])),
    ]
    for _ in range(2):
        parts += [
            (2 * p.hip_link_mass, np.array([0.0, hip_z])),
            (p.thigh_mass, 0.5 * (np.array([0.0, hip_z]) + knee)),
            (p.shank_mass, 0.5 * (knee + ankle)),
            (HUB_MASS / 2, ankle),
            (p.foot_mass, np.array([0.0, foot_h / 2])),
        ]
    m = sum(w for w, _ in parts)
    c = sum(w * x for w, x in parts) / m
    return float(c[0]), float(c[1])


def test_model_mass_and_com_match_the_dataclass() -> None:
    p = BipedModel()
    info = measure_model(p)
    assert abs(info.mass - (p.total_mass + HUB_MASS)) < MASS_TOL
    x, z = _analytic_com(p)
    assert abs(info.com_height - z) < COM_TOL
    assert abs(info.com_offset[0] - x) < COM_TOL
    assert abs(info.com_offset[1]) < COM_TOL


def test_model_scales_with_the_dataclass() -> None:
    heavy = BipedModel(torso_mass=20.0)
    assert abs(measure_model(heavy).mass - measure_model().mass - 6.0) < MASS_TOL


def test_planner_params_come_from_the_model() -> None:
    p = BipedModel()
    info = measure_model(p)
    robot = planner_params(p)
    assert robot.mass == info.mass
    assert robot.com_height == info.com_height
    assert robot.stance_width == p.hip_width
    u_foot = U_MAX_FOOT_SHARE * info.mass * robot.g * p.foot_width / 2
    assert robot.u_max == pytest.approx(min(BipedParams().u_max, u_foot))
    # the bound keeps a planned ZMP (tau / m g) inside the sole's half width
    assert robot.u_max / (robot.mass * robot.g) < p.foot_width / 2


def test_every_named_element_exists() -> None:
    m = mujoco.MjModel.from_xml_string(biped_mjcf())
    obj = mujoco.mjtObj
    names = [(obj.mjOBJ_BODY, nm.PELVIS_BODY), (obj.mjOBJ_BODY, nm.TORSO_BODY)]
    for s in (Side.LEFT, Side.RIGHT):
        names += [(obj.mjOBJ_JOINT, nm.joint(s, j)) for j in nm.LEG_JOINTS]
        names += [(obj.mjOBJ_ACTUATOR, nm.actuator(s, j)) for j in nm.LEG_JOINTS]
        names += [(obj.mjOBJ_SITE, nm.sole_site(s))]
        names += [(obj.mjOBJ_GEOM, nm.corner_geom(s, k)) for k in range(4)]
    for kind, name in names:
        assert mujoco.mj_name2id(m, kind, name) >= 0, name
    assert m.nu == 12


@pytest.mark.parametrize(
    ("field", "kwargs"),
    [
        ("model.thigh_mass", {"thigh_mass": -1.0}),
        ("model.nominal_hip_height", {"nominal_hip_height": 2.0}),
        ("model.corner_radius", {"corner_radius": 0.06}),
        ("model.torso_size", {"torso_size": (0.1, 0.2)}),
        ("model.joint_range[knee]", {"joint_range": ((0, 1),) * 3 + ((1, 0),) + ((0, 1),) * 2}),
    ],
)
def test_bad_model_parameters_name_the_field(field: str, kwargs: dict[str, object]) -> None:
    with pytest.raises(InputError) as err:
        BipedModel(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def _terrain_model(terrain: Terrain) -> tuple[object, object]:
    m = mujoco.MjModel.from_xml_string(biped_mjcf(terrain=terrain_xml(terrain)))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return m, d


def _ray_height(m: object, d: object, xy: np.ndarray) -> float:
    """Height of the first terrain surface below ``xy`` (robot geoms excluded), or -inf."""
    top = 5.0
    groups = np.zeros(6, dtype=np.uint8)
    groups[nm.TERRAIN_GROUP] = 1
    gid = np.zeros(1, dtype=np.int32)
    dist = mujoco.mj_ray(
        m, d, np.array([xy[0], xy[1], top]), np.array([0, 0, -1.0]), groups, 1, -1, gid
    )
    return -math.inf if dist < 0 else top - dist


@pytest.mark.parametrize("name", builtin_scene_names())
def test_terrain_surfaces_are_the_region_planes(name: str) -> None:
    scene = builtin_scene(name)
    m, d = _terrain_model(scene.terrain)
    rng = np.random.default_rng(0)
    for region in scene.terrain.regions:
        for _ in range(SAMPLES):
            # random convex combination of the corners, kept off the edges where neighbours meet
            w = rng.dirichlet(np.ones(len(region.vertices)))
            xy = 0.9 * (w @ region.vertices) + 0.1 * region.centroid[:2]
            assert abs(_ray_height(m, d, xy) - region.height_at(xy)) < HEIGHT_TOL


def test_gaps_are_holes() -> None:
    scene = builtin_scene("stairs_slope_gap")
    m, d = _terrain_model(scene.terrain)
    # the 0.12 m gap between the ledge (x <= 3.2) and the landing (x >= 3.32)
    assert _ray_height(m, d, np.array([3.26, 0.0])) == -math.inf


def test_a_non_rectangular_region_becomes_a_prism() -> None:
    tri = Region.from_3d("tri", [[0.0, 0.0, 0.1], [1.0, 0.0, 0.2], [0.0, 1.0, 0.15]])
    m, d = _terrain_model(Terrain((tri,)))
    gid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, nm.region_geom("tri"))
    assert m.geom_type[gid] == mujoco.mjtGeom.mjGEOM_MESH
    for xy in ([0.2, 0.2], [0.5, 0.1], [0.1, 0.6]):
        assert abs(_ray_height(m, d, np.array(xy)) - tri.height_at(xy)) < HEIGHT_TOL

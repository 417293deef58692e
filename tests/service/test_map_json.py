"""The map's JSON written from its columns equals the model's serialisation, byte for byte.

``POST /v1/map`` writes its body with :func:`service.convert.map_json.map_json` (no model per
cell, issue 23); the contract is :class:`service.schemas.MapResponse`. Every kind of cell:
feasible and each reason, named and numeric branches, joint acceleration limits (mu_acc and
what binds it), free spin with several spins, a grid with no feasible cell (best and worst
null), and odd numbers (small and large magnitudes, negative zero).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from service.convert import map_response
from service.convert.map_json import cell_pages, map_json
from solver.core.robots import Robot
from solver.families import get_robot
from solver.path.problem import SpinMode
from tests.problems import capability_map
from tests.solver.families.numeric_maps import ur5_from_urdf
from tests.solver.test_evaluate import load_path

XS = np.array([-0.9, -1e-7, -0.0, 0.2, 0.45])
YS = np.array([0.3, 0.55, 9.5e2])
YAWS = np.array([0.0, math.pi / 3])


def _robots() -> dict[str, tuple[Robot, SpinMode, np.ndarray]]:
    ur5 = get_robot("ur5")
    return {
        "ur5 fixed": (ur5, "fixed", np.zeros(1)),
        "ur5 free, two spins": (ur5, "free", np.array([0.0, 0.7])),
        "accelerations": (ur5.with_options(qddot_max=[10.0] * 6), "fixed", np.zeros(1)),
        "kr6 wrist limits": (get_robot("kuka_kr6_r700_sixx"), "fixed", np.zeros(1)),
        "numeric ur5": (ur5_from_urdf(), "fixed", np.zeros(1)),
    }


ROBOTS = _robots()


@pytest.mark.parametrize("name", ROBOTS)
def test_the_written_body_is_the_models(name: str) -> None:
    robot, spin_mode, spins = ROBOTS[name]
    path = load_path("curved_line")[:: 8 if name == "numeric ur5" else 1]
    cmap = capability_map(
        robot, path, spin_mode=spin_mode, xs=XS, ys=YS, z=0.1, yaws=YAWS, spins=spins
    )
    assert (cmap.reason == -1).any() and (cmap.reason >= 0).any()  # both kinds of cell
    expected = map_response(cmap, robot, spin_mode=spin_mode).model_dump_json()
    assert map_json(cmap, robot, spin_mode=spin_mode) == expected.encode()


def test_a_map_without_a_feasible_cell() -> None:
    robot = get_robot("ur5e")
    far = np.array([5.0, 6.0])
    cmap = capability_map(robot, load_path("curved_line"), xs=far, ys=far, z=0.1, yaws=YAWS)
    assert not (cmap.reason == -1).any()
    expected = map_response(cmap, robot, spin_mode="fixed").model_dump_json()
    assert '"best":null' in expected
    assert map_json(cmap, robot, spin_mode="fixed") == expected.encode()


@pytest.mark.parametrize("page", [1, 7, 13, 1000])
def test_pages_of_any_size_join_to_the_routes_cells(page: int) -> None:
    """A map job stores its cells a page at a time (service.convert.map_json.cell_pages): pages
    that cut rows of x anywhere hold, in order, the cells the route answers."""
    robot, spin_mode, spins = ROBOTS["accelerations"]
    cmap = capability_map(
        robot, load_path("curved_line"), spin_mode=spin_mode, xs=XS, ys=YS, z=0.1, yaws=YAWS,
        spins=spins,
    )  # fmt: skip
    pages = list(cell_pages(cmap, robot, page=page))
    assert len(pages) == -(-cmap.mu_path.size // page)
    cells = [cell for text in pages for cell in json.loads(f"[{text}]")]
    expected = map_response(cmap, robot, spin_mode=spin_mode).model_dump(mode="json")["cells"]
    assert cells == expected

"""The NLP's assembled derivatives equal casadi's differentiation of the whole problem (issue 12).

IPOPT gets the constraint Jacobian and the Lagrangian's Hessian assembled from each waypoint's
own (``derivatives=True``, the default). The reference is the same NLP with ``derivatives=False``:
casadi's algorithmic differentiation of the whole MX graph, what IPOPT was given before. Both are
evaluated at random points, with random multipliers, on every form of the problem: fixed spin,
free spin, a spin path, a seven-joint arm, and a program of two passes.
"""

from __future__ import annotations

import math

import casadi
import numpy as np
import pytest

from solver.families import get_robot
from solver.optimise.methods.placement_nlp import PlacementNlp
from solver.optimise.search_space import PlacementBounds
from tests.problems import problem
from tests.solver.test_evaluate import load_path

BOUNDS = PlacementBounds(x=(-0.25, 0.25), y=(0.25, 0.65), yaw=(-math.pi, math.pi), z=0.1)
FORMS = {
    "fixed": ("ur5", {}, None),
    "free spin": ("ur5", {"free_spin": True}, None),
    "spin path": ("ur5e", {"max_spin_step": 0.1}, None),
    "seven joints": ("panda", {}, None),
    "two passes": ("ur5", {}, [(0, 4), (4, 9)]),
    "accelerations": ("ur5", {"accelerations": 10.0}, None),
}


def _dense(matrix: casadi.DM) -> np.ndarray:
    return np.array(casadi.densify(matrix))


@pytest.mark.parametrize("form", FORMS)
def test_assembled_derivatives_equal_casadis_own(form: str) -> None:
    name, options, passes = FORMS[form]
    robot, path = get_robot(name), load_path("curved_line")[:9]
    options = dict(options)
    spin_mode = "free" if options.pop("free_spin", False) else "fixed"
    if "accelerations" in options:
        robot = robot.with_options(qddot_max=[options.pop("accelerations")] * robot.dof)
    posed = problem(
        robot, path, passes=passes, max_joint_step=0.3, spin_mode=spin_mode, blend_length=0.003
    )
    built = {
        own: PlacementNlp(posed, BOUNDS, derivatives=own, **options)._solver
        for own in (True, False)
    }
    jacobians = {own: solver.get_function("nlp_jac_g") for own, solver in built.items()}
    hessians = {own: solver.get_function("nlp_hess_l") for own, solver in built.items()}
    rng = np.random.default_rng(3)
    for _ in range(3):
        x = rng.normal(size=jacobians[True].size1_in(0))
        weights = rng.normal(size=hessians[True].size1_in(3))
        g, jacobian = jacobians[True](x, [])
        g_ref, jacobian_ref = jacobians[False](x, [])
        np.testing.assert_allclose(_dense(g), _dense(g_ref), rtol=0, atol=1e-12)
        scale = 1.0 + np.abs(_dense(jacobian_ref)).max()
        np.testing.assert_allclose(
            _dense(jacobian), _dense(jacobian_ref), rtol=0, atol=1e-13 * scale
        )
        hessian = hessians[True](x, [], 0.7, weights)
        hessian_ref = hessians[False](x, [], 0.7, weights)
        assert hessian.sparsity().is_triu()
        reference = np.triu(_dense(hessian_ref))
        scale = 1.0 + np.abs(reference).max()
        np.testing.assert_allclose(_dense(hessian), reference, rtol=0, atol=1e-13 * scale)

"""Joint acceleration limits bounded by their blend's span (audit 21, finding 1).

The compiled kernels form each stencil row's D from the steps its blend spans. They held the
steps' weights as a (K, S) table and its transpose, S the longest row's span, made at every
kernel call: a one-placement map of a 20,000-waypoint path whose blend spanned half of it
allocated 1.6 GB. Now a row reads its own span from four runs of equal weight
(:func:`solver.kernels.limits.step_stencil`).
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np

from tests.cases import ROOT


def test_a_one_placement_map_of_a_dense_blend_stays_small() -> None:
    # audit 21: one placement, 20,000 waypoints of which 4,000 lie within 2 mm (the default
    # blend spans all of them): the kernel grew the process by 1.6 GB; run in a process of its
    # own, whose peak resident size is read before and after
    script = textwrap.dedent(
        """
        import resource, sys
        import numpy as np
        sys.path.insert(0, sys.argv[1])
        from solver.families import get_robot
        from solver.path.capability_map import capability_map
        from solver.path.problem import PathProblem
        s = np.concatenate([
            np.linspace(0.0, 0.159, 8000, endpoint=False),
            np.linspace(0.159, 0.161, 4000, endpoint=False),
            np.linspace(0.161, 0.32, 8000),
        ])
        poses = np.tile(np.diag([1.0, -1.0, -1.0, 1.0]), (len(s), 1, 1))
        poses[:, 0, 3] = s - 0.16
        robot = get_robot("ur5").with_options(qddot_max=[10.0] * 6)
        problem = PathProblem.of(robot, poses)
        one = np.array([0.0])
        warm = PathProblem.of(robot, poses[::400])  # the kernels loaded, on a small stencil
        capability_map(warm, xs=one, ys=one + 0.45, z=0.1, yaws=one)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        cmap = capability_map(problem, xs=one, ys=one + 0.45, z=0.1, yaws=one)
        after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(after - before, cmap.reason.ravel()[0], cmap.mu_acc.ravel()[0])
        """
    )
    run = subprocess.run(
        [sys.executable, "-c", script, str(ROOT)],
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    grown_kib, reason, mu_acc = run.stdout.split()
    assert int(reason) == -1 and np.isfinite(float(mu_acc))  # feasible: the scan ran
    assert int(grown_kib) < 200 * 1024, f"grew {int(grown_kib) / 1024:.0f} MiB"

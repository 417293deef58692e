"""How fast a checked pair can close in, per joint: what lets a map skip configurations.

A point at most r from a joint's axis moves at most r |dq| when the joint turns by dq (|dq|
when it slides). So between two configurations a pair's distance changes by at most
sum_j w_pj |dq_j|, with w_pj a bound on the distance from joint j's axis to the part that joint
j moves relative to the other object: the chain's length from joint j to the part's joint plus
the part's extent from its joint (the triangle inequality). A pair at distance d is then clear
at every configuration within sum_j w_pj |dq_j| < d - clearance (conservative advancement).

Against a ``fixed`` halfspace (the table top) only the motion along its normal n counts: a turn
dq about an axis k moves every point within the plane normal to k, whose component along n is
at most |n x k| of the move. For a joint whose axis is fixed in the world (its parent is the
root: a serial arm's first joint), |n x k| is a constant, and w_pj takes that factor: the first
joint of an arm standing on its table (k = n) does not move any part towards the table at all,
so the upper arm's distance to it is checked when q2 moves, and the shoulder's, all of whose
weights are zero, not at all (:mod:`solver.path.cell.scene`: it stands on the table, as the
base does).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from solver.core.kinematics import revolute_axis


def _lever(model: pin.Model, joint: int, carrier: int) -> float:
    """Bound on the distance from ``joint``'s origin to ``carrier``'s origin along the chain."""
    chain = list(model.supports[carrier])
    after = chain[chain.index(joint) + 1 :]
    return float(sum(np.linalg.norm(model.jointPlacements[k].translation) for k in after))


def _extent(obj: pin.GeometryObject) -> float:
    """Bound on the distance from an object's joint origin to any of its points (m).

    The ball about its local bounding box's centre (``aabb_center``, in the geometry's frame)
    of radius ``aabb_radius``, placed on the joint: a mesh's box is not centred on its origin
    (the UR5's upper arm: 0.213 m along z, so 0.50 m where the ball about the origin said 0.29).
    """
    obj.geometry.computeLocalAABB()
    placement = obj.placement
    centre = placement.translation + placement.rotation @ np.asarray(obj.geometry.aabb_center)
    return float(np.linalg.norm(centre)) + float(obj.geometry.aabb_radius)


def _world_axis(model: pin.Model, joint: int) -> np.ndarray | None:
    """A revolute joint's axis in the world where it is fixed there (its parent the root)."""
    if model.parents[joint] != 0:
        return None
    local = revolute_axis(model, joint)
    if local is None:
        return None
    axis: np.ndarray = np.asarray(model.jointPlacements[joint].rotation) @ local
    unit: np.ndarray = axis / np.linalg.norm(axis)
    return unit


def _halfspace_normal(obj: pin.GeometryObject) -> np.ndarray | None:
    """A halfspace obstacle's unit normal in the world; None for any other shape."""
    if type(obj.geometry).__name__ != "Halfspace":
        return None
    normal: np.ndarray = np.asarray(obj.placement.rotation) @ np.asarray(obj.geometry.n)
    unit: np.ndarray = normal / np.linalg.norm(normal)
    return unit


def pair_weights(
    model: pin.Model,
    geometry: pin.GeometryModel,
    pairs: list[tuple[int, int]],
    n_robot: int,
    *,
    n_fixed: int = 0,
) -> np.ndarray:
    """W (P, nv), m/rad (m/m for a prismatic joint): see the module docstring.

    Args:
        model: the robot's model.
        geometry: its geometry objects first (``n_robot`` of them), then the obstacles.
        pairs: (robot part, other object) index pairs; the other is an obstacle (static within
            a path) when its index is ``n_robot`` or more.
        n_robot: how many of the objects are the robot's.
        n_fixed: how many obstacles after the robot's objects are at their final pose (the
            cell's ``fixed`` ones; a halfspace among them takes the factor |n x k| above).
    """
    objects = geometry.geometryObjects
    weights = np.zeros((len(pairs), model.nv))
    # Each lever, extent and joint's support set once: computed a pair at a time, 100 collision
    # elements among 100 objects (12,717 pairs) took 2.5 s of a checker's build, 60 % of it
    # here, before the size limits could refuse the request (stop 61). The same numbers.
    levers: dict[tuple[int, int], float] = {}
    extents: dict[int, float] = {}
    supported: dict[int, set[int]] = {}
    for p, (a, b) in enumerate(pairs):
        moving = [a] if b >= n_robot else [a, b]
        supports = []
        for g in moving:
            carrier = int(objects[g].parentJoint)
            if carrier not in supported:
                supported[carrier] = set(model.supports[carrier])
            supports.append(supported[carrier])
        normal = _halfspace_normal(objects[b]) if n_robot <= b < n_robot + n_fixed else None
        for k, g in enumerate(moving):
            carrier = int(objects[g].parentJoint)
            others = supports[1 - k] if len(moving) == 2 else {0}
            if g not in extents:
                extents[g] = _extent(objects[g])
            for joint in supports[k] - others - {0}:
                if (joint, carrier) not in levers:
                    levers[joint, carrier] = _lever(model, joint, carrier)
                reach = levers[joint, carrier] + extents[g]
                prismatic = model.joints[joint].shortname().startswith("JointModelP")
                axis = None if normal is None else _world_axis(model, joint)
                if normal is not None and axis is not None:  # only the move along the normal
                    reach *= float(np.linalg.norm(np.cross(normal, axis)))
                weights[p, model.joints[joint].idx_v] += max(reach, 1.0) if prismatic else reach
    return weights

"""How fast a checked pair can close in, per joint: what lets a map skip configurations.

A point at most r from a joint's axis moves at most r |dq| when the joint turns by dq (|dq|
when it slides). So between two configurations a pair's distance changes by at most
sum_j w_pj |dq_j|, with w_pj a bound on the distance from joint j's axis to the part that joint
j moves relative to the other object: the chain's length from joint j to the part's joint plus
the part's extent from its joint (the triangle inequality). A pair at distance d is then clear
at every configuration within sum_j w_pj |dq_j| < d - clearance (conservative advancement).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


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


def pair_weights(
    model: pin.Model, geometry: pin.GeometryModel, pairs: list[tuple[int, int]], n_robot: int
) -> np.ndarray:
    """W (P, nv), m/rad (m/m for a prismatic joint): see the module docstring.

    Args:
        model: the robot's model.
        geometry: its geometry objects first (``n_robot`` of them), then the obstacles.
        pairs: (robot part, other object) index pairs; the other is an obstacle (static within
            a path) when its index is ``n_robot`` or more.
        n_robot: how many of the objects are the robot's.
    """
    objects = geometry.geometryObjects
    weights = np.zeros((len(pairs), model.nv))
    for p, (a, b) in enumerate(pairs):
        moving = [a] if b >= n_robot else [a, b]
        supports = [set(model.supports[int(objects[g].parentJoint)]) for g in moving]
        for k, g in enumerate(moving):
            carrier = int(objects[g].parentJoint)
            others = supports[1 - k] if len(moving) == 2 else {0}
            for joint in supports[k] - others - {0}:
                reach = _lever(model, joint, carrier) + _extent(objects[g])
                prismatic = model.joints[joint].shortname().startswith("JointModelP")
                weights[p, model.joints[joint].idx_v] += max(reach, 1.0) if prismatic else reach
    return weights

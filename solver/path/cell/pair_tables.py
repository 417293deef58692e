"""Tabulated lower bounds of robot self pairs whose bounding capsules overlap (issue 22).

A robot part b on joint j_b and a part a on an ancestor joint j_a are apart by a distance that
depends only on the joints between them (q_k for k on the chain after j_a up to j_b): the joints
before j_a turn both parts alike, the others neither. Where the parts' capsules overlap at most
configurations (the UR5's base and upper arm, its forearm and second wrist, its first and third
wrist), the sweep (:mod:`solver.path.cell.sweep`) needed their meshes' support functions at
every configuration it checked. For such a pair with one or two chain joints, all revolute, coal's
distance is tabulated once on a grid of those joints over a turn (2 pi periodic); with three
(the UR5's forearm and third wrist), part b is replaced by the cylinder about j_b's axis that
holds it at every angle (no nearer to part a than b is), on j_b's parent: two joints. Then

    d(q) >= T[g] - MARGIN - sum_k w_k |q_k - g_k|

at the grid point g nearest q (conservative advancement, :mod:`solver.path.cell.bounds`):
turning joint k by dq moves the points of one part relative to the other by at most w_k |dq|,
and coal's distance is the exact one within :data:`solver.path.cell.fast.MARGIN`. w_k is the
pair's weight (:func:`solver.path.cell.bounds.pair_weights`), or smaller where k's axis is fixed
to a part: the first chain joint's axis is fixed in part a's frame (then turning it moves part a
relative to b by at most a's largest distance from that axis), the last one's (j_b) in b's frame;
a part's largest distance from a line is its convex mesh's vertices' (else its bounding box's
corners'), plus coal's swept sphere radius.

The pack (:func:`table_bound`): per pair its table or -1 (P,); per table the q indices (T, 2),
the grid counts (T, 2), the weights (T, 2) (a second dimension unused: index 0, count 1,
weight 0), the offsets (T + 1,) into the values (V,), row-major.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import coal
import numpy as np
import pinocchio as pin
from numba import njit

from solver.path.cell.bounds import pair_weights
from solver.path.cell.closed_form import segment_segment
from solver.path.cell.kept_tables import Row, keep_row, kept_row
from solver.path.cell.kernel_cache import drop_stale_cell_kernels

drop_stale_cell_kernels()  # the kernels here take callees and constants of other modules in

# Grid points of a table (coal distances made once per checker: about 6 microseconds each, the
# UR5's five tables 0.45 s on a loaded machine).
BUDGET = 1 << 14
# A pair is tabulated when its capsules come within the clearance at this fraction or more of
# random configurations (seeded): where the sweep would need its meshes at most checks (the
# UR5: 1.0, 1.0, 1.0, 0.72 and 0.48 for the pairs tabulated, 0.3 or less for the others).
OVERLAP = 0.4
_SAMPLES = 64
_TURN = 2.0 * math.pi
TablePack = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def table_bound(t, q, tables, margin):  # type: ignore[no-untyped-def]  # pragma: no cover - compiled
    """A lower bound (m) on table t's pair's distance at configuration q (n,), rad."""
    q_index, counts, weights, offsets, values = tables[1:]
    flat, slack = 0, margin
    for d in range(2):
        n = counts[t, d]
        step = _TURN / n
        x = q[q_index[t, d]]
        r = math.floor(x / step + 0.5)
        slack += weights[t, d] * abs(x - r * step)
        flat = flat * n + int(r - n * math.floor(r / n))
    return values[offsets[t] + flat] - slack


def empty_tables(n_pairs: int) -> TablePack:
    """A pack with no table."""
    return (
        np.full(n_pairs, -1, dtype=np.int64),
        np.zeros((0, 2), dtype=np.int64),
        np.ones((0, 2), dtype=np.int64),
        np.zeros((0, 2)),
        np.zeros(1, dtype=np.int64),
        np.zeros(0),
    )


def _points(obj: pin.GeometryObject) -> tuple[np.ndarray, float]:
    """Points (k, 3) in the object's joint frame whose convex hull holds it, and its inflation.

    A convex mesh's vertices; else its bounding box's corners. The inflation (m): coal's swept
    sphere radius, every point of the object within it of the hull.
    """
    shape = obj.geometry
    if isinstance(shape, coal.ConvexBase):
        local = np.asarray(shape.points(), dtype=float).reshape(-1, 3)
    else:
        shape.computeLocalAABB()
        low = np.asarray(shape.aabb_local.min_, dtype=float)
        high = np.asarray(shape.aabb_local.max_, dtype=float)
        local = np.array([[(low, high)[(i >> k) & 1][k] for k in range(3)] for i in range(8)])
    at = local @ np.asarray(obj.placement.rotation).T + np.asarray(obj.placement.translation)
    return at, float(shape.getSweptSphereRadius())


def _largest_from_axis(obj: pin.GeometryObject, origin: np.ndarray, axis: np.ndarray) -> float:
    """Bound (m) on any point of the object's distance from a line.

    The line: through ``origin`` along the unit ``axis``, in the object's joint frame.
    """
    at, inflation = _points(obj)
    along = (at - origin) @ axis
    squared = np.sum((at - origin) ** 2, axis=1) - along**2
    return float(np.sqrt(np.max(squared).clip(0.0))) + inflation


def _revolved(
    model: pin.Model, obj: pin.GeometryObject, joint: int, axis: np.ndarray
) -> pin.GeometryObject:
    """A cylinder about ``joint``'s axis holding ``obj`` at every angle, on the joint's parent.

    ``obj`` is on ``joint``; the cylinder is what it sweeps turning about the axis (``axis``
    in the joint's frame, through its origin) and more: a part's distance to another is at
    least the cylinder's, whatever the joint's angle.
    """
    at, inflation = _points(obj)
    along = at @ axis
    radius = float(np.sqrt(np.max(np.sum(at**2, axis=1) - along**2).clip(0.0))) + inflation
    low, high = float(along.min()) - inflation, float(along.max()) + inflation
    z = axis / np.linalg.norm(axis)
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    frame = pin.SE3(np.column_stack([x, np.cross(z, x), z]), z * (low + high) / 2.0)
    cylinder = coal.Cylinder(radius, max(high - low, 1e-9))
    placement = model.jointPlacements[joint] * frame
    return pin.GeometryObject(
        f"{obj.name}_revolved", int(model.parents[joint]), placement, cylinder
    )


def _chain(model: pin.Model, ja: int, jb: int, kind: np.ndarray) -> list[int] | None:
    """The joints after ja up to jb (ja an ancestor of jb), if one to three and all revolute."""
    supports = list(model.supports[jb])
    if ja == jb or ja not in supports:
        return None
    chain = supports[supports.index(ja) + 1 :]
    return chain if 1 <= len(chain) <= 3 and all(kind[k] == 1 for k in chain) else None


def _overlap(robot: tuple[np.ndarray, ...], model: pin.Model, a: int, b: int, near: float) -> float:
    """The fraction of seeded random configurations where a's and b's capsules come within near."""
    rng = np.random.default_rng(0)
    data = model.createData()
    joint, local, radius = robot[6], robot[7], robot[8]
    close = 0
    for _ in range(_SAMPLES):
        pin.forwardKinematics(model, data, rng.uniform(-math.pi, math.pi, model.nq))
        ends = [local[r] @ data.oMi[int(joint[r])].rotation.T + data.oMi[int(joint[r])].translation
                for r in (a, b)]  # fmt: skip
        close += segment_segment(*ends[0], *ends[1]) - radius[a] - radius[b] <= near
    return close / _SAMPLES


def build_tables(
    model: pin.Model,
    geometry: pin.GeometryModel,
    robot: tuple[np.ndarray, ...],
    pairs: np.ndarray,
    weights: np.ndarray,
    near: float,
    keys: Sequence[str] | None = None,
) -> TablePack:
    """The tables of the self pairs that need them (module docstring).

    Args:
        model: the robot's model.
        geometry: the checker's geometry (robot parts first).
        robot: the sweep's robot pack (:class:`solver.path.cell.fast.FastCell`).
        pairs: shape (P, 2), the checked pairs.
        weights: shape (P, nv), :func:`solver.path.cell.bounds.pair_weights`.
        near: m, the clearance plus the margin: capsules within it go to the meshes.
        keys: the robot parts' content keys (:class:`solver.path.cell.robot_geometry.
            RobotGeometry`): a table of two parts already made is taken from those kept; None
            makes every table.
    """
    n_robot, kind, axes = len(robot[8]), robot[3], robot[4]
    objects = geometry.geometryObjects
    table_of = np.full(len(pairs), -1, dtype=np.int64)
    rows: list[Row] = []
    for p, (a, b) in enumerate(pairs):
        if b >= n_robot or (robot[9][a] and robot[9][b]):
            continue
        ja, jb = int(robot[6][a]), int(robot[6][b])
        if ja in model.supports[jb]:
            first, second = int(a), int(b)
        else:
            first, second, ja, jb = int(b), int(a), jb, ja
        chain = _chain(model, ja, jb, kind)
        if chain is None or _overlap(robot, model, first, second, near) < OVERLAP:
            continue
        key = None if keys is None else (keys[first], keys[second])
        made = kept_row(key)
        if made is None:
            made = _row(model, objects[first], objects[second], chain, weights[p], axes)
            if made is None:
                continue
            keep_row(key, made)
        rows.append(made)
        table_of[p] = len(rows) - 1
    if not rows:
        return empty_tables(len(pairs))
    pad = [(r[0] + [0], r[1] + [1], r[2] + [0.0]) for r in rows]
    return (
        table_of,
        np.array([r[0][:2] for r in pad], dtype=np.int64),
        np.array([r[1][:2] for r in pad], dtype=np.int64),
        np.array([r[2][:2] for r in pad], dtype=float),
        np.concatenate([[0], np.cumsum([r[3].size for r in rows])]).astype(np.int64),
        np.concatenate([r[3].ravel() for r in rows]),
    )


def _row(
    model: pin.Model,
    a_obj: pin.GeometryObject,
    b_obj: pin.GeometryObject,
    chain: list[int],
    row: np.ndarray,
    axes: np.ndarray,
) -> Row | None:
    """A pair's table: q indices, grid counts, weights, coal's distances; None if it has none.

    Args:
        model: the robot's model.
        a_obj: the part on the ancestor joint.
        b_obj: the other part.
        chain: the joints after a_obj's up to b_obj's (:func:`_chain`).
        row: the pair's weights (P's row of :func:`solver.path.cell.bounds.pair_weights`).
        axes: the sweep's joint axes (its robot pack's).
    """
    if len(chain) == 3:  # the last joint's part as the cylinder it sweeps
        b_obj, chain = _revolved(model, b_obj, chain[2], axes[chain[2]]), chain[:2]
        probe = pin.GeometryModel()
        probe.addGeometryObject(a_obj)
        probe.addGeometryObject(b_obj)
        row = pair_weights(model, probe, [(0, 1)], 2)[0]
    w = [float(row[model.joints[k].idx_v]) for k in chain]
    placement = model.jointPlacements[chain[0]]
    axis = np.asarray(placement.rotation) @ axes[chain[0]]
    w[0] = min(w[0], _largest_from_axis(a_obj, placement.translation, axis))
    w[-1] = min(w[-1], _largest_from_axis(b_obj, np.zeros(3), axes[chain[-1]]))
    if not all(math.isfinite(wk) and wk > 0.0 for wk in w):
        return None  # a joint moving neither part: no grid to size; the sweep's bounds decide
    scale = (BUDGET / math.prod(w)) ** (1.0 / len(chain))
    counts = [max(4, int(scale * wk)) for wk in w]
    q_index = [model.joints[k].idx_q for k in chain]
    return q_index, counts, w, _tabulate(model, a_obj, b_obj, q_index, counts)


def _tabulate(
    model: pin.Model,
    first: pin.GeometryObject,
    second: pin.GeometryObject,
    q_index: list[int],
    counts: list[int],
) -> np.ndarray:
    """Coal's distance of the two objects at every grid point, shape ``counts``."""
    probe = pin.GeometryModel()
    probe.addGeometryObject(first)
    probe.addGeometryObject(second)
    probe.addCollisionPair(pin.CollisionPair(0, 1))
    data, gdata = model.createData(), probe.createData()
    values = np.empty(math.prod(counts))
    q = pin.neutral(model)
    grids = [np.arange(n) * (_TURN / n) for n in counts]
    flat = 0
    for x in grids[0]:
        q[q_index[0]] = x
        for y in grids[1] if len(grids) > 1 else [0.0]:
            if len(grids) > 1:
                q[q_index[1]] = y
            pin.updateGeometryPlacements(model, data, probe, gdata, q)
            values[flat] = pin.computeDistance(probe, gdata, 0).min_distance
            flat += 1
    return values.reshape(counts)

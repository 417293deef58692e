"""Coal's working copies of a checker's geometry, one per thread, reused across placements.

A map's cell check asks coal for a few distances on most refused paths, each at its own
placement. Copying the geometry and making its data for every such path cost about 0.16 ms
(``GeometryModel.createData`` 0.12 ms, ``Model.createData`` 0.04 ms, UR5 in the ERK cell),
several times the distances themselves. Each thread keeps one copy and its data; a placement
only moves the ``workpiece`` objects (``updateGeometryPlacements`` recomputes every object's
world pose from the model's placements on each call, so nothing else carries over).
"""

from __future__ import annotations

import threading

import pinocchio as pin


class CoalData:
    """Per thread: a copy of the geometry, its ``GeometryData`` and the model's ``Data``."""

    def __init__(
        self, model: pin.Model, geometry: pin.GeometryModel, workpiece: list[tuple[int, pin.SE3]]
    ) -> None:
        """Keep what the copies are made of.

        Args:
            model: the robot's model.
            geometry: the checker's geometry (robot parts, then the obstacles).
            workpiece: (geometry index, pose in {O}) of each ``workpiece`` object.
        """
        self._model, self._geometry, self._workpiece = model, geometry, workpiece
        self._local = threading.local()

    def at(self, placed: pin.SE3) -> tuple[pin.GeometryModel, pin.GeometryData, pin.Data]:
        """This thread's copy with the workpiece objects at ``placed`` (T_world_O), its data."""
        made = getattr(self._local, "made", None)
        if made is None:
            geometry = self._geometry.copy()
            made = (geometry, geometry.createData(), self._model.createData())
            self._local.made = made
        for gid, pose in self._workpiece:
            made[0].geometryObjects[gid].placement = placed * pose
        return made

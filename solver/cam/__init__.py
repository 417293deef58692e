"""CAM paths read from files (cam.md sections 5, 6 and 8).

:mod:`solver.cam.cl_data` reads APT CL data, :mod:`solver.cam.csv_path` a CSV path, both into a
:class:`solver.cam.cam_path.CamPath`; :mod:`solver.cam.frames` writes a placement in the terms
of robot controllers.
"""

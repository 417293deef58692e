"""The science: robot models, IK, task requirements, DTF, mu_path (numpy/pinocchio)."""

from pathlib import Path

from solver.core.cache_home import settle_cache_folder

# Before any module's compiled functions are declared: numba needs a cache folder at once.
settle_cache_folder(Path(__file__))

"""The science: robot models, IK, task requirements, DTF, mu_path (numpy/pinocchio)."""

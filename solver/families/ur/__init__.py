"""UR arms: analytic IK with eight branches and a closed-form J^-1 t (robots.md section 2)."""

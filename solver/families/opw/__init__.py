"""OPW arms: industrial six-axis arms with a spherical wrist (robots.md section 3)."""

"""Numeric IK for any serial arm (robots.md section 4): chain, LM solver, family, catalogue."""

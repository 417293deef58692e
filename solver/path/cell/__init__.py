"""The cell: obstacles, the tool and the robot's own geometry along a joint path (cell.md)."""

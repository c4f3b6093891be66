"""Step 2 of a run: a robot's signals (pose, velocity, scan, distance, goals) wherever its
convention puts them, on one timeline."""

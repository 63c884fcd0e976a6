"""The world model: the resolved `World` (every body, sensor and stream of a run, built once
from a scenario), waves, terrain, geodesy, environment fields, placement, the traffic plan."""

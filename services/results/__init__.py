"""`catabot results`: one table of many runs, a row per run and scenario vessel, for sweeps."""

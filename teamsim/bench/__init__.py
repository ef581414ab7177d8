"""``teamsim bench ...``: figures and ratios measured in one run (physics, cleanup, render, nav, alliance,
allocate, sweep)."""

"""Studies: each sweeps a mission or a physics-free world over the conditions of a thesis's experiment and
writes a report beside the published numbers."""

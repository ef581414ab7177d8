"""Chand's hybrid navigation (ch.3-4): occupancy grid, modified A* and two-tiered A*, direction sensor
(polar histogram), modified dynamic window, and a plain dynamic window as the reference."""

"""Missions in physics: each sets up the world (arena and team), gives each robot a controller, says when the
trial is over and whether it succeeded, and measures it."""

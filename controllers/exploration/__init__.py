"""Chand's multi-robot map building and exploration (ch.6): the explorer's coverage waypoints and bog
detection, the planners' local-environment assignment and mutual exclusion, the manager's job queue, global map
merge and environment status, and the three roles as agents that talk over the network."""

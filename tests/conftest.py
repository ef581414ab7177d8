"""Test session set-up: pick the GL backend before anything imports mujoco."""
import teamsim  # noqa: F401

"""Skills every mission may use: locomotion (a (v, omega) command to actuators), the hexapod gait, go-to and
obstacle avoidance, the gripper, dead-reckoned pose estimates, wandering."""

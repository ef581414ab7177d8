"""The janitorial service's behaviour sets (Parker §6.2): empty-garbage, dust-furniture, clean-floor, and the
robot that runs them under ALLIANCE."""

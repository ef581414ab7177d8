"""Controllers: what robots *do*. Each turns an Observation into a Command and never reads MjData."""

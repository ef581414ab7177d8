"""Each mission's behaviour sets, one module per mission: what the robots do in it (today the hazardous-waste
cleanup's)."""

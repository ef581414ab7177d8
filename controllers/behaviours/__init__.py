"""Each mission's behaviour sets, one module per mission: what the robots do in it: the hazardous-waste
cleanup, box pushing, and the janitorial service (a package of its own)."""

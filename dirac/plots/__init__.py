"""Pictures of the motion (matplotlib, headless): polhodes, body axes, conserved-quantity errors."""

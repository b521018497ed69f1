"""Step 5: gauge generators (Castellani) and gauge fixing."""

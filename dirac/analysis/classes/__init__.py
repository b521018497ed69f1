"""Step 3: the multipliers in general form and the first/second-class split."""

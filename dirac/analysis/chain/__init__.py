"""Step 2: the Dirac–Bergmann constraint chain, stage by stage, and the parameter values
where its ranks drop."""

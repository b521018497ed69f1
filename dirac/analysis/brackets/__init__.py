"""Step 4: the Dirac bracket, brackets in chosen variables and the Dirac vector field."""

"""Step 1 of the algorithm: the input Lagrangian made regular, and the Legendre map
(momenta, Hessian, primary constraints, canonical Hamiltonian)."""

"""Integration methods: the base classes (:mod:`~dirac.flows.methods.base`), one module per
family, the state every family of a problem kind shares, and the registry of names
(:mod:`~dirac.flows.methods.registry`)."""

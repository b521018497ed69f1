"""Integration methods: the base classes, one module per family, and the registry."""

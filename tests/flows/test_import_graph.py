"""The method registry imports the family modules, never the other way.

The whole package is checked for cycles and layers in tests/test_layers.py; this file
guards what is particular to the integrators.
"""

from __future__ import annotations

from import_graph import import_graph


def test_family_modules_do_not_import_the_registry():
    graph = import_graph()
    for module, imported in graph.items():
        if module.startswith("dirac.flows.methods.") and module not in (
            "dirac.flows.methods.registry",
            "dirac.flows.methods.auto",
        ):
            assert "dirac.flows.methods.registry" not in imported, module
    assert "dirac.flows.methods.heavy_top" not in graph["dirac.flows.methods.lie_poisson"]

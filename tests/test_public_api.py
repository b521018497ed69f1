"""The lazy public names of `dirac` resolve to the objects the public API (docs/api.md) promises."""

from __future__ import annotations

import inspect

import dirac


def test_every_public_name_resolves_and_is_not_a_module():
    for name in dirac.__all__:
        value = getattr(dirac, name)
        assert not inspect.ismodule(value), f"dirac.{name} is a module, not the public object"
        assert callable(value) or name == "TIME", f"dirac.{name} is not callable"


def test_time_is_the_real_symbol_t_the_engine_uses():
    import sympy

    from dirac.model.expressions import TIME

    assert dirac.TIME is TIME and dirac.TIME == sympy.Symbol("t", real=True)
    assert dirac.TIME != sympy.Symbol("t")  # sympy's plain t (and dynamicsymbols._t) is another symbol


def test_unknown_attribute_is_an_attribute_error():
    try:
        dirac.no_such_name  # noqa: B018 -- the attribute access itself is what is tested
    except AttributeError as exc:
        assert "no_such_name" in str(exc)
    else:
        raise AssertionError("dirac.no_such_name did not raise AttributeError")


def test_flows_integrate_is_the_function_whatever_was_imported_first():
    # regression: the module dirac.flows.integration and the function once shared the name `integrate`
    import dirac.flows.integration
    from dirac.flows import integrate

    assert callable(integrate) and not inspect.ismodule(integrate)
    assert integrate is dirac.integrate


def test_version_comes_from_the_installed_distribution():
    from importlib.metadata import version

    assert dirac.__version__ == version("dirac-mechanics")
    assert "__version__" in dir(dirac)


def test_dir_lists_the_public_names_and_no_import_leftovers():
    listed = set(dir(dirac))
    assert set(dirac.__all__) <= listed
    assert not {"annotations", "lazy_exports", "errors"} & listed

"""``dirac analyze FILE`` for a [field] system file: text, JSON (the field-theory keys), LaTeX, --gauge, errors."""

from __future__ import annotations

import json

from dirac.fields.catalog import MAXWELL_DENSITY

MAXWELL_FILE = f'''[field]
name = "maxwell"
space = ["x", "y", "z"]
fields = ["A0", "A1", "A2", "A3"]
density = "{MAXWELL_DENSITY}"
'''


def _write(tmp_path, text, name="theory.toml"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_json_has_per_point_counts_field_theory_keys_and_the_zero_mode_case(tmp_path, run_cli):
    """Maxwell in 3+1: 2 dof per point, Gauss law in position space, k = 0 with 3 dof per mode
    (hand counts in test_field_linear_theories.py)."""
    status, out, err = run_cli("analyze", _write(tmp_path, MAXWELL_FILE), "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["physical_degrees_of_freedom"] == 2
    assert data["field_theory"]["method"] == "fourier"
    assert data["field_theory"]["wave_vector"] == ["k_x", "k_y", "k_z"]
    assert data["field_theory"]["fields"] == ["A0", "A1", "A2", "A3"]
    assert data["stages"][1]["constraints"] == ["d_x(p_A1) + d_y(p_A2) + d_z(p_A3)"]
    assert data["gauge_transformations"][0]["delta"]["A1"] == "d_x(epsilon)"
    cases = data["parameter_cases"]
    assert cases[0]["physical_degrees_of_freedom"] == 2  # the generic case first
    assert cases[1]["condition"] == "k_x = k_y = k_z = 0" and cases[1]["physical_degrees_of_freedom"] == 3


def test_text_and_latex(tmp_path, run_cli):
    path = _write(tmp_path, MAXWELL_FILE)
    status, out, _ = run_cli("analyze", path)
    assert status == 0
    assert "d_x(p_A1) + d_y(p_A2) + d_z(p_A3) = 0" in out
    assert "physical degrees of freedom per spatial point: 2" in out
    assert "delta A0 = epsilon_t" in out
    status, out, _ = run_cli("analyze", path, "--latex")
    assert status == 0 and r"\partial_{x} p_{A_{1}}" in out and r"\delta A_{0} &= \dot{\epsilon}" in out


def test_gauge_in_the_density_syntax_gives_the_transverse_delta(tmp_path, run_cli):
    """Coulomb gauge: {A1, p_A2}_D = -k_x k_y / k^2 (the transverse delta, hand derivation in
    test_field_linear_theories.py)."""
    status, out, err = run_cli("analyze", _write(tmp_path, MAXWELL_FILE), "--gauge", "A0", "--gauge", "A1_x + A2_y + A3_z",
                               "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["gauge_conditions"] == ["A0", "A1_x + A2_y + A3_z"]
    assert data["first_class"] == []
    assert data["dirac_brackets"]["{A1, p_A2}"] == "-k_x*k_y/(k_x**2 + k_y**2 + k_z**2)"


def test_bad_input_exits_2_with_an_error_line(tmp_path, run_cli):
    bad = MAXWELL_FILE.replace("A0_x)**2", "A0_w)**2")
    status, _, err = run_cli("analyze", _write(tmp_path, bad))
    assert status == 2 and err.startswith("error:") and "'A0_w'" in err and "not a declared direction" in err
    quartic = '[field]\nname = "phi4"\nspace = ["x"]\nfields = ["phi"]\ndensity = "phi_t**2/2 - phi_x**2/2 - phi**4"\n'
    status, _, err = run_cli("analyze", _write(tmp_path, quartic, "q.toml"))
    assert status == 2 and err.startswith("error:") and "--lattice N" in err


def test_unused_field_is_a_warning_line(tmp_path, run_cli):
    text = '[field]\nname = "kg"\nspace = ["x"]\nfields = ["phi", "chi"]\ndensity = "phi_t**2/2 - phi_x**2/2"\n'
    status, out, err = run_cli("analyze", _write(tmp_path, text), "--json")
    assert status == 0
    assert err.startswith("warning:") and "'chi'" in err


def test_lattice_flag_on_a_nonlinear_theory(tmp_path, run_cli):
    """The O(3) sigma model on a ring of 4 sites: per site the multiplier's momentum, n.n = 1 and its
    two time derivatives (4 second class), 2 dof per site (hand count in test_field_lattice.py)."""
    text = ('[field]\nname = "sigma"\nspace = ["x"]\nfields = ["n1", "n2", "n3"]\n'
            'density = "(n1_t**2 + n2_t**2 + n3_t**2)/2 - (n1_x**2 + n2_x**2 + n3_x**2)/2"\n'
            'constraints = ["n1**2 + n2**2 + n3**2 - 1"]\n')
    status, out, err = run_cli("analyze", _write(tmp_path, text), "--lattice", "4", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert len(data["second_class"]) == 16 and data["physical_degrees_of_freedom"] == 8
    assert data["coordinates"][:3] == ["n1_0", "n2_0", "n3_0"]


def test_gauge_errors_speak_of_the_conditions_given(tmp_path, run_cli):
    path = _write(tmp_path, MAXWELL_FILE)
    status, _, err = run_cli("analyze", path, "--gauge", "p_A0")
    assert status == 2 and err.startswith("error: gauge conditions p_A0") and "fixes nothing" in err
    status, _, err = run_cli("analyze", path, "--gauge", "A1_t")
    assert status == 2 and "use the momenta p_<field>, not time derivatives" in err
    status, _, err = run_cli("analyze", path, "--gauge", "A0**2")
    assert status == 2 and "must be linear and homogeneous" in err
    status, _, err = run_cli("analyze", path, "--cases")
    assert status == 2 and err.startswith("error:")


def test_json_gauge_generator_terms_in_position_space(tmp_path, run_cli):
    """Castellani's generator of Maxwell, by hand: G = int (eps_dot pi^0 - eps d_i pi_i), so G_0 = -d_i pi_i
    and G_1 = pi^0 (the terms multiply eps and eps_dot)."""
    status, out, _ = run_cli("analyze", _write(tmp_path, MAXWELL_FILE), "--json")
    assert json.loads(out)["gauge_generators"] == [{"terms": ["-d_x(p_A1) - d_y(p_A2) - d_z(p_A3)", "p_A0"]}]


def test_lattice_flag_refused_for_a_mechanical_system(tmp_path, run_cli):
    path = _write(tmp_path, '[system]\nname = "p"\ncoordinates = ["x"]\nlagrangian = "x_dot**2/2"\n', "p.toml")
    status, _, err = run_cli("analyze", path, "--lattice", "4")
    assert status == 2 and "--lattice needs a field theory" in err

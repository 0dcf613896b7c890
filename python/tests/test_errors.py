"""Bad input raises ValueError (InputError) with the command line's one-line message; numerical
failures raise RuntimeError (NumericalError); nothing, however absurd, aborts the interpreter."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import restitution as rs
from conftest import DATA, cli_error, run_cli


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize(
    "text",
    [
        "# comment\nd_mm,v_n_m_s,e\n\n12.7,1.0,0.95\n12.7,0,97,0.9\n",  # wrong field count
        "d_mm,v_n_m_s,e\n12.7,1.0,0.95\n12.7,2.0,0;9\n",  # not a number
        "d_mm,v_n_m_s,e\n12.7,1.0,0.95\n12.7,-2.0,0.9\n",  # out of range
        "d_mm,v_n_m_s,e,e_err\n12.7,1.0,0.95,0.01\n12.7,2.0,0.9,nan\n",  # NaN text
        "d_mm,v_n_m_s\n12.7,1.0\n",  # missing column
        "d_mm,v_n_m_s,e\n",  # no rows
    ],
)
def test_bad_fit_files_give_the_cli_message(tmp_path, monkeypatch, text):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, "bad.csv", text)
    want = cli_error("fit", "bad.csv", "--material", "nylon")
    with pytest.raises(ValueError) as info:
        rs.fit("bad.csv", "nylon")
    assert str(info.value) == want
    assert isinstance(info.value, rs.InputError)


def test_file_errors_carry_the_place(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, "bad.csv", "# c\nd_mm,v_n_m_s,e\n12.7,1,0.9\n\n12.7,2,x\n")
    with pytest.raises(rs.InputError) as info:
        rs.fit("bad.csv", "nylon")
    e = info.value
    assert (e.path, e.line, e.column, e.kind) == ("bad.csv", 5, "e", "value")
    assert str(e) == "bad.csv:5: column 'e': 'x' is not a number"


def test_missing_file_and_strict_give_the_cli_message(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError) as info:
        rs.fit("missing.csv", "nylon")
    assert str(info.value) == cli_error("fit", "missing.csv", "--material", "nylon")
    assert info.value.kind == "io"
    write(tmp_path, "hi.csv", "d_mm,v_n_m_s,e\n12.7,1,1.02\n12.7,2,0.9\n12.7,3,0.9\n")
    with pytest.raises(ValueError) as info:
        rs.fit("hi.csv", "nylon", strict=True)
    assert str(info.value) == cli_error("fit", "hi.csv", "--material", "nylon", "--strict")


def test_bad_walton_and_tracks_files_give_the_cli_message(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, "w.csv", "d1_mm,d2_mm\n25.4,25.4\n")
    with pytest.raises(ValueError) as info:
        rs.walton_fit("w.csv", "nylon")
    assert str(info.value) == cli_error("walton", "fit", "w.csv", "--material", "nylon")
    write(tmp_path, "t.csv", "collision,t_s,x1_m,y1_m,x2_m,y2_m,d1_mm,d2_mm\na,0,0,0,1,0,10,nan\n")
    with pytest.raises(ValueError) as info:
        rs.kinematics("t.csv", "nylon")
    assert str(info.value) == cli_error("kinematics", "t.csv", "--material", "nylon")


def test_table_errors_name_the_row():
    pd = pytest.importorskip("pandas")
    df = pd.DataFrame(
        {"d_mm": [12.7, 12.7, 12.7], "v_n_m_s": [1.0, 2.0, np.nan], "e": [0.9, 0.9, 0.9]},
        index=["a", "b", "c"],
    )
    with pytest.raises(
        rs.InputError,
        match=r"^<DataFrame>: row 'c': column 'v_n_m_s': empty \(a missing value\): a number is required$",
    ):
        rs.fit(df, "nylon")
    with pytest.raises(
        rs.InputError,
        match=r"^<dict>: row 1: column 'e': empty \(a missing value\): a number is required$",
    ):
        rs.fit({"d_mm": [12.7, 12.7], "v_n_m_s": [1, 2], "e": [0.9, None]}, "nylon")
    with pytest.raises(rs.InputError, match=r"^<dict>: row 1: column 'e': '-0.5' is out of range"):
        rs.fit({"d_mm": [12.7, 12.7], "v_n_m_s": [1, 2], "e": [0.9, -0.5]}, "nylon")
    with pytest.raises(rs.InputError, match="different lengths"):
        rs.fit({"d_mm": [12.7], "v_n_m_s": [1, 2], "e": [0.9, 0.9]}, "nylon")
    with pytest.raises(TypeError):
        rs.fit(42, "nylon")


def test_table_errors_about_its_columns_name_no_row():
    # The header line of the table's CSV text is no row of the table: these had said "row -1",
    # and "header" and "file" where the user gave a table.
    cases = [
        (lambda: rs.fit({"d_mm": [12.7], "v_n_m_s": [1]}, "nylon"),
         "<dict>: column 'e': required column is missing (the table has: d_mm,v_n_m_s)"),
        (lambda: rs.fit({"d_mm": [], "v_n_m_s": [], "e": []}, "nylon"),
         "<dict>: the table has no rows"),
        (lambda: rs.fit({}, "nylon"), "<dict>: the table has no columns"),
        (lambda: rs.walton_fit({"d1_mm": [25.4]}, "nylon"),
         "<dict>: column 'd2_mm': required column is missing (the table has: d1_mm)"),
        (lambda: rs.kinematics({"collision": [], "t_s": []}, "nylon"),
         "<dict>: the table has no rows"),
    ]
    for call, message in cases:
        with pytest.raises(rs.InputError) as info:
            call()
        assert str(info.value) == message
        assert info.value.row is None


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: rs.e_of_kappa([0.1, -1.0]), "kappa[1] = -1: expected a number >= 0"),
        (lambda: rs.e_of_kappa([np.inf]), "kappa[0] = inf: expected a number >= 0"),
        (lambda: rs.e_of_u([np.nan]), "u[0] = NaN: expected a number >= 0"),
        (lambda: rs.e_of_kappa(1.0, contact_end="never"), "contact_end: 'never' is not a contact-end rule: expected overlap or force"),
        (lambda: rs.e_of_kappa(1.0, method="euler"), "method 'euler': expected master, dop853 or dopri5"),
        (lambda: rs.e_of_kappa(1.0, method="dop853", tol=2.0), "tol = 2: expected a number in [1e-15, 1)"),
        (lambda: rs.e_of_kappa(1.0, method="dop853", tol=1e-25), "tol = 1e-25: expected a number in [1e-15, 1)"),
        (lambda: rs.predict("vm", [1.0], d_mm=10, material="nylon"), "model='vm' needs eta (kg/(s m))"),
        (lambda: rs.predict("vm", [1.0], d_mm=10, material="unobtainium", eta=1), "material 'unobtainium' is not a preset: expected one of nylon, steel, glass, aluminium"),
        (lambda: rs.predict("vm", [1.0], d_mm=10, material="nylon", eta=-5), "eta = -5: invalid damping eta (kg/(s m)) = -5: expected a finite number >= 0"),
        (lambda: rs.predict("pm", [0.0], d_mm=10, material="nylon", sigma_y_pa=1e7), "v_m_s[0] = 0: expected a speed > 0 (m/s)"),
        (lambda: rs.predict("xx", [1.0]), "model 'xx': expected vm or pm"),
        (lambda: rs.predict("vm", [1.0], kappa=[1.0]), "give exactly one of v_m_s, kappa (vm) or u (pm)"),
        (lambda: rs.e_of_kappa("abc"), None),
        # numpy would keep the real part with only a ComplexWarning.
        (lambda: rs.e_of_kappa([0.1, 1 + 1j]), "kappa: expected real numbers, got complex values"),
        (lambda: rs.predict("vm", np.array([2j]), d_mm=10, material="nylon", eta=1), "v_m_s: expected real numbers, got complex values"),
        (lambda: rs.fit("x.csv", "nylon", model="cubic"), "model 'cubic': expected vm, pm, min, product, powerlaw or all"),
        (lambda: rs.walton_fit("x.csv", "nylon", bootstrap=1), "bootstrap = 1: expected 0 (no intervals) or at least 2 resamples"),
        (lambda: rs.kinematics("x.csv", "nylon", pixels_x=0), "pixels_x = 0: expected a pixel count > 0"),
        (lambda: rs.kinematics("x.csv", "nylon", inertia_k=1e300), "inertia_k = 1e300: expected a number in (0, 1] (K = 4I/(m d^2); 0.4 for a homogeneous sphere)"),
        (lambda: rs.kinematics("x.csv", "nylon", fixed_gravity=True, g_m_s2=1e300), "g_m_s2 = 1e300: expected a number > 0, at most 1e6 m/s^2 (1e5 g, a centrifuge's)"),
        (lambda: rs.walton_fit("x.csv", "nylon", inertia_k=2.0), "inertia_k = 2: expected a number in (0, 1] (K = 4I/(m d^2); 0.4 for a homogeneous sphere)"),
    ],
)
def test_bad_arguments_raise_value_error(call, message):
    with pytest.raises(ValueError) as info:
        call()
    if message is not None:
        assert str(info.value) == message


def same_error(cli_line, py_message):
    """One message, with the input named as each front end names it: `--d-mm 1e-300: why` on the
    command line, `d_mm = 1e-300: why` in Python."""
    name, rest = py_message.split(" = ", 1)
    value, why = rest.split(": ", 1)
    return cli_line == f"restitution: error: --{name.replace('_', '-')} {value}: {why}"


@pytest.mark.parametrize(
    "model, flags, kwargs",
    [
        ("pm", {"--d-mm": 1e-300, "--sigma-y-pa": 1e300}, dict(d_mm=1e-300, sigma_y_pa=1e300)),
        ("vm", {"--d-mm": 1e-300, "--eta": 190}, dict(d_mm=1e-300, eta=190.0)),
        ("vm", {"--d-mm": 1e300, "--eta": 1e-300}, dict(d_mm=1e300, eta=1e-300)),
        ("pm", {"--d-mm": 1e300, "--sigma-y-pa": 1e-300}, dict(d_mm=1e300, sigma_y_pa=1e-300)),
    ],
)
def test_absurd_values_do_what_the_cli_does(model, flags, kwargs):
    """Same numbers or the same error as the command line, whatever the library makes of it."""
    v = [1e-300, 1.0, 1e300]
    args = ["predict", "--model", model, "--material", "nylon", "--format", "csv"]
    for k, x in flags.items():
        args += [k, repr(float(x))]
    p = run_cli(*args, "--v-m-s", ",".join(map(repr, v)), check=False)
    try:
        _, cols = rs.predict(model, v, material="nylon", full_output=True, **kwargs)
    except ValueError as err:
        assert p.returncode != 0 and same_error(p.stderr.strip(), str(err)), (p.stderr, str(err))
        return
    assert p.returncode == 0, p.stderr
    head, *rows = [line.split(",") for line in p.stdout.splitlines()]
    assert head == list(cols)
    for j, name in enumerate(head):
        want = [float(r[j]) for r in rows]
        assert np.array_equal(cols[name], want, equal_nan=True), name


def test_numerical_failure_is_a_runtime_error():
    # Above kappa = 2000 (overlap rule) the ODE refuses: its tolerances do not resolve e there
    # (the master curve, the default, covers every kappa). An error value, as on the command line.
    with pytest.raises(RuntimeError, match="integration failed at kappa = 100000"):
        rs.e_of_kappa([1.0, 1e5], method="dop853")


def test_a_panic_becomes_a_runtime_error():
    with pytest.raises(RuntimeError, match="internal error .*deliberate panic"):
        rs._restitution._panic_for_test()


def test_absurd_input_never_aborts_the_interpreter(tmp_path):
    # In a child interpreter: an abort or a panic escaping the guard would kill it, which an
    # in-process test could not report.
    rows = "\n".join(f"12.7,{1 + i % 37},0.9" for i in range(100_000))
    (tmp_path / "big.csv").write_text("d_mm,v_n_m_s,e\n" + rows + "\n12.7,2,NaN\n")
    script = textwrap.dedent(
        f"""
        import numpy as np, restitution as rs
        bad = [0.0, -0.0, 1e-300, 1e300, -1e300, np.nan, np.inf, -np.inf, 5e-324]
        calls = []
        for x in bad:
            calls += [
                lambda x=x: rs.e_of_kappa([x]),
                lambda x=x: rs.e_of_u([x]),
                lambda x=x: rs.predict("vm", [x], d_mm=10, material="nylon", eta=190),
                lambda x=x: rs.predict("vm", [1.0], d_mm=x, material="nylon", eta=190),
                lambda x=x: rs.predict("vm", [1.0], d_mm=10, material="nylon", eta=x),
                lambda x=x: rs.predict("pm", [1.0], d_mm=10, d2_mm=x, material="nylon", sigma_y_pa=1e7),
                lambda x=x: rs.predict("pm", [1.0], d_mm=10, youngs_pa=x, poisson=0.3, density_kg_m3=1000, sigma_y_pa=x),
                lambda x=x: rs.fit({{"d_mm": [12.7] * 3, "v_n_m_s": [1, 2, x], "e": [0.9, 0.8, 0.7]}}, "nylon"),
                lambda x=x: rs.fit({{"d_mm": [x] * 3, "v_n_m_s": [1, 2, 3], "e": [0.9, 0.8, 0.7]}}, "nylon", model="vm"),
                lambda x=x: rs.kinematics("{tmp_path / 'big.csv'}", "nylon", g_m_s2=x),
            ]
        calls.append(lambda: rs.fit("{tmp_path / 'big.csv'}", "nylon"))
        ok = errors = 0
        for c in calls:
            try:
                c()
                ok += 1
            except (ValueError, RuntimeError):
                errors += 1
        print("survived", ok, errors)
        """
    )
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("survived"), p.stdout


def test_huge_speeds_give_an_error_not_a_panic():
    # Once a panic (capacity overflow in the fit's old scan), on the command line too.
    with pytest.raises(ValueError):
        rs.fit({"d_mm": [12.7] * 3, "v_n_m_s": [1, 2, 1e300], "e": [0.9, 0.8, 0.7]}, "nylon", model="pm")


def test_a_walton_row_that_breaks_momentum_is_named(tmp_path, monkeypatch):
    # The shipped collisions with one post-collision velocity mistyped (-1e40 m/s): the fit runs,
    # and the warning the CLI prints names the row, here as in the command line.
    monkeypatch.chdir(tmp_path)
    lines = (DATA / "oblique_collisions.csv").read_text().splitlines()
    head = next(i for i, l in enumerate(lines) if not l.startswith("#"))
    cols = lines[head].split(",")
    cells = lines[head + 1].split(",")
    cells[cols.index("v1x_post_m_s")] = "-1e40"
    lines[head + 1] = ",".join(cells)
    write(tmp_path, "typo.csv", "\n".join(lines) + "\n")
    r = rs.walton_fit("typo.csv", "nylon", bootstrap=0)
    [w] = r.warnings
    assert w.startswith(f"typo.csv:{head + 2}: collision '1': ") and "momentum is not conserved" in w
    assert rs.walton_fit(DATA / "oblique_collisions.csv", "nylon", bootstrap=0).warnings == []

"""`restitution.export` against `restitution export`: the same library job, so the same files
byte for byte, the same export.json and the same report; and the Python-only inputs (a fit's
result instead of a params.json) give the same law."""

import json
import os
import shutil

import pytest

import restitution as rs
from conftest import DATA, ROOT, run_cli

PARAMS = "reports/fit/params.json"
WALTON = "reports/walton/walton.json"

# The CLI runs and the Python calls the README shows, one per engine and law source.
CASES = [
    (
        ["--engine", "lammps", "--v-range", "0.5,40", "--tolerance", "0.01", "--walton", WALTON],
        dict(engine="lammps", v_range=(0.5, 40), tolerance=0.01, walton=WALTON),
    ),
    (
        ["--engine", "constant-e", "--v-range", "0.5,2", "--weight", "uniform", "--mu0", "0.3"],
        dict(engine="constant-e", v_range=(0.5, 2), weight="uniform", mu0=0.3),
    ),
    (
        ["--engine", "table", "--v-range", "0.5,40", "--table-points", "7", "--d-mm", "6.35,25.4", "--wall"],
        dict(engine="table", v_range=(0.5, 40), table_points=7, d_mm=[6.35, 25.4], wall=True),
    ),
]


@pytest.mark.parametrize("flags,kwargs", CASES)
def test_files_equal_the_cli(in_root, tmp_path, flags, kwargs):
    cli_dir, py_dir = tmp_path / "cli", tmp_path / "py"
    printed = run_cli("export", PARAMS, *flags, "--out", cli_dir).stdout
    r = rs.export(PARAMS, out=py_dir, **kwargs)
    cli_files = sorted(p.name for p in cli_dir.iterdir())
    assert sorted(p.name for p in py_dir.iterdir()) == cli_files
    assert sorted(r.files) == cli_files
    for name in cli_files:
        assert (py_dir / name).read_bytes() == (cli_dir / name).read_bytes(), name
        assert r.files[name] == (cli_dir / name).read_bytes(), name
    assert r.to_dict() == json.loads((cli_dir / "export.json").read_text())
    assert r.report == printed


def test_law_given_as_numbers_equals_the_cli(in_root, tmp_path):
    flags = ["--engine", "lammps", "--material", "nylon", "--d-mm", "6.35,25.4", "--wall",
             "--eta", "2000", "--contact-end", "force", "--speeds", "0.5,3,20"]
    run_cli("export", *flags, "--out", tmp_path / "cli")
    r = rs.export(engine="lammps", material="nylon", d_mm=[6.35, 25.4], wall=True, eta=2000.0,
                  contact_end="force", speeds_m_s=[0.5, 3, 20], out=tmp_path / "py")
    for name in ("in.restitution", "collide.in", "export.json"):
        assert r.files[name] == (tmp_path / "cli" / name).read_bytes(), name
    assert r.to_dict()["source"] == "the numbers given"


def test_a_fit_result_exports_as_its_params_json(in_root):
    # The fit of the shipped data, in memory, gives the law its params.json gives.
    fitted = rs.fit(DATA / "fig7_nylon.csv", "nylon")
    from_result = rs.export(fitted, engine="table", v_range=(0.5, 40)).to_dict()
    from_file = rs.export(PARAMS, engine="table", v_range=(0.5, 40)).to_dict()
    assert from_result.pop("source") == "<FitResult> (model min)"
    assert from_file.pop("source") == f"{PARAMS} (model min)"
    assert from_result == from_file


def test_without_out_nothing_is_written_and_export_json_is_not_listed(in_root, tmp_path):
    r = rs.export(PARAMS, engine="table", v_range=(0.5, 40))
    assert "export.json" not in r.files and "export.json" not in r.to_dict()["files"]
    assert r.text("table.csv").startswith("pair,d1_mm,d2_mm,v_n_m_s,e\n")


@pytest.mark.parametrize(
    "kwargs,message",
    [
        (dict(engine="table"), "model min has no exact engine form: give the scene's speeds with v_range LO,HI"),
        (dict(engine="table", model="vm"), "this engine needs the scene's speeds: v_range LO,HI"),
        (dict(engine="lammps", tolerance=0.01), "tolerance needs v_range LO,HI"),
        (dict(engine="teleport"), "engine 'teleport': expected one of lammps, constant-e, table"),
        (dict(engine="table", v_range=(0.5, 40), d_mm=-1.0),
         "d_mm -1: expected a finite number > 0"),
        (dict(engine="lammps", eta=5.0), f"eta comes from {PARAMS} (give either params or the numbers)"),
        (dict(engine="table", v_range=(0.5, 40), mu0=float("nan")), "mu0 NaN: expected a finite number >= 0"),
        (dict(engine="table", v_range=(40, 0.5)), "v_range (40, 0.5): "),
    ],
)
def test_bad_arguments_raise_input_error_naming_the_keyword(in_root, kwargs, message):
    with pytest.raises(rs.InputError) as err:
        rs.export(PARAMS, **kwargs)
    assert str(err.value).startswith(message), str(err.value)


def test_the_cli_names_the_flag_where_python_names_the_keyword(in_root):
    p = run_cli("export", PARAMS, "--engine", "lammps", "--tolerance", "0.01", check=False)
    assert p.returncode != 0
    assert "--tolerance needs --v-range LO,HI" in p.stderr


def test_a_failed_write_leaves_nothing(in_root, tmp_path):
    # `out` is a file, not a directory: an error, and no file is created beside it.
    blocker = tmp_path / "taken"
    blocker.write_text("x")
    with pytest.raises(rs.InputError, match="out .*taken"):
        rs.export(PARAMS, engine="table", v_range=(0.5, 40), out=blocker)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken"]


def test_verify_runs_lammps_and_agrees(in_root):
    # CI installs LAMMPS, so there a missing `lmp` is a failure, not a skip.
    if shutil.which("lmp") is None:
        if os.environ.get("CI"):
            pytest.fail("CI=true but LAMMPS (lmp) is not on PATH")
        pytest.skip("LAMMPS (lmp) is not installed")
    r = rs.export(PARAMS, engine="lammps", model="vm", verify=True)
    rows = r.to_dict()["lammps_verify"]
    # Three speeds for each of the fit's three sizes' six pairs.
    assert len(rows) == 18
    assert all(abs(row["difference"]) <= rs.VERIFY_TOLERANCE for row in rows)
    assert r.verify_table is not None and len(r.verify_table.splitlines()) > len(rows)

"""The Python results are the command line's, bit for bit: parsed JSON documents compared with
==, which for floats means equal doubles (json round-trips a double exactly both ways)."""

import numpy as np
import pytest

import restitution as rs
from conftest import DATA, cli_json, run_cli


def same(a, b, path="doc"):
    """Recursive exact equality with a readable failure (NaN never appears: the documents
    write null)."""
    if isinstance(a, dict) and isinstance(b, dict):
        assert list(a) == list(b), f"{path}: keys {list(a)} != {list(b)}"
        for k in a:
            same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        assert len(a) == len(b), f"{path}: lengths {len(a)} != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{path}[{i}]")
    else:
        assert type(a) is type(b) and a == b, f"{path}: {a!r} != {b!r}"


@pytest.mark.parametrize(
    "file, args, kwargs",
    [
        ("data/fig7_nylon.csv", [], {}),
        ("data/fig7_nylon.csv", ["--contact-end", "force"], {"contact_end": "force"}),
        ("data/wall_example.csv", [], {}),
        ("data/fig7_nylon.csv", ["--model", "vm", "--exact"], {"model": "vm", "exact": True}),
    ],
)
def test_fit_document_equals_cli_json(in_root, file, args, kwargs):
    with pytest.warns(rs.DataWarning) if "fig7" in file else _nothing():
        r = rs.fit(file, "nylon", **kwargs)
    same(r.to_dict(), cli_json("fit", file, "--material", "nylon", *args))


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *a):
        return False


def test_fit_from_dataframe_and_dict_equals_the_file(in_root):
    pd = pytest.importorskip("pandas")
    cli = cli_json("fit", "data/fig7_nylon.csv", "--material", "nylon")
    df = pd.read_csv(DATA / "fig7_nylon.csv", comment="#")
    for data, name in [(df, "<DataFrame>"), ({k: df[k].to_numpy() for k in df}, "<dict>")]:
        with pytest.warns(rs.DataWarning, match=r"row 0: column 'e': '1.0613' is above 1"):
            doc = rs.fit(data, "nylon").to_dict()
        assert doc["data"]["path"] == name
        doc["data"]["path"] = cli["data"]["path"]
        same(doc, cli)


def test_fit_with_constants_instead_of_a_preset(in_root):
    args = ["--youngs-pa", "3.5e8", "--poisson", "0.3", "--density-kg-m3", "1140"]
    r = rs.fit("data/wall_example.csv", youngs_pa=3.5e8, poisson=0.3, density_kg_m3=1140, model="vm")
    same(r.to_dict(), cli_json("fit", "data/wall_example.csv", *args, "--model", "vm"))


def test_fit_figures_and_reports_equal_cli_out(in_root, tmp_path):
    run_cli("fit", "data/fig7_nylon.csv", "--material", "nylon", "--out", tmp_path)
    with pytest.warns(rs.DataWarning):
        r = rs.fit("data/fig7_nylon.csv", "nylon")
    assert r.fig7_svg() == (tmp_path / "fig7.svg").read_text()
    assert r.residuals_svg() == (tmp_path / "residuals.svg").read_text()
    assert r.markdown() == (tmp_path / "params.md").read_text()
    assert r.csv() == (tmp_path / "params.csv").read_text()
    assert r.text() == run_cli("fit", "data/fig7_nylon.csv", "--material", "nylon").stdout
    same(r.to_dict(), __import__("json").loads((tmp_path / "params.json").read_text()))


def test_fit_accessors_read_the_document(in_root):
    r = rs.fit("data/wall_example.csv", "nylon")
    doc = r.to_dict()
    assert r.preferred == doc["preferred"]
    eta = next(f for f in doc["fits"] if f["model"] == "vm")["params"]["eta"]
    p = r.params["vm"]["eta"]
    assert (p["value"], p["stderr"], p["interval"]) == (eta["value"], eta["stderr"], tuple(eta["ci95"]))
    t = r.table()
    rows = t.to_dict("records") if hasattr(t, "to_dict") else t
    assert sum(len(f["params"]) for f in doc["fits"]) == len(rows)
    html = r._repr_html_()
    assert "<svg" in html and "preferred" in html
    assert r.unranked is None


def test_exact_fits_leave_no_model_preferred():
    # Three identical rows at one speed: every model reproduces them to rounding, and AIC
    # (n ln(RSS/n) + 2k, -inf for two of them) has nothing to rank.
    r = rs.fit({"d_mm": [10, 10, 10], "v_n_m_s": [1, 1, 1], "e": [0.9, 0.9, 0.9]}, "nylon")
    assert r.preferred is None
    assert "reproduce the points to rounding" in r.unranked
    assert all(c["delta_aic"] is None for c in r.to_dict()["comparison"])


def predict_rows(*args):
    return cli_json("predict", *args)


@pytest.mark.parametrize(
    "cli_args, kwargs",
    [
        (["--model", "vm", "--material", "nylon", "--d-mm", "25.4", "--eta", "190"],
         dict(model="vm", material="nylon", d_mm=25.4, eta=190.0)),
        (["--model", "vm", "--material", "steel", "--d-mm", "3", "--d2-mm", "7", "--eta", "1e4",
          "--contact-end", "force"],
         dict(model="vm", material="steel", d_mm=3, d2_mm=7, eta=1e4, contact_end="force")),
        (["--model", "vm", "--material", "nylon", "--d-mm", "12.7", "--wall", "--eta", "190",
          "--method", "dopri5", "--tol", "1e-9"],
         dict(model="vm", material="nylon", d_mm=12.7, wall=True, eta=190.0, method="dopri5", tol=1e-9)),
        (["--model", "pm", "--material", "nylon", "--d-mm", "6.35", "--sigma-y-pa", "4e7"],
         dict(model="pm", material="nylon", d_mm=6.35, sigma_y_pa=4e7)),
        (["--model", "pm", "--youngs-pa", "2e11", "--poisson", "0.29", "--density-kg-m3", "7800",
          "--d-mm", "10", "--wall", "--sigma-y-pa", "1e9"],
         dict(model="pm", youngs_pa=2e11, poisson=0.29, density_kg_m3=7800, d_mm=10, wall=True,
              sigma_y_pa=1e9)),
    ],
)
def test_predict_equals_cli_columns(cli_args, kwargs):
    v = [0.01, 0.5, 2.0, 6.3233, 10.0, 40.0, 300.0]
    rows = predict_rows(*cli_args, "--v-m-s", ",".join(map(repr, v)))
    e, cols = rs.predict(v_m_s=v, full_output=True, **kwargs)
    assert list(cols) == list(rows[0])
    for name, values in cols.items():
        assert values.tolist() == [r[name] for r in rows], name
    assert e.tolist() == [r["e"] for r in rows]


@pytest.mark.parametrize("rule", ["overlap", "force"])
def test_dimensionless_equal_cli(rule):
    kappa = [0.0, 1e-8, 1e-3, 0.5, 5.0, 99.0, 250.0]
    rows = predict_rows("--model", "vm", "--kappa", ",".join(map(repr, kappa)), "--contact-end", rule)
    _, cols = rs.predict("vm", kappa=kappa, contact_end=rule, full_output=True)
    assert list(cols) == list(rows[0])
    for name, values in cols.items():
        assert values.tolist() == [r[name] for r in rows], name
    assert rs.e_of_kappa(kappa, contact_end=rule).tolist() == [r["e"] for r in rows]
    u = [0.0, 1.0, 1.0 + 1e-12, 1.5, 10.0, 1e12]
    rows = predict_rows("--model", "pm", "--u", ",".join(map(repr, u)))
    assert rs.e_of_u(u).tolist() == [r["e"] for r in rows]


def test_walton_numbers_equal_cli_json(in_root):
    args = ["data/oblique_collisions.csv", "--material", "nylon", "--bootstrap", "200", "--seed", "3"]
    cli = cli_json("walton", "fit", *args)
    w = rs.walton_fit("data/oblique_collisions.csv", "nylon", bootstrap=200, seed=3)
    # The same document, bit for bit (both are the library's data::report::walton::to_json).
    assert w.to_dict() == cli
    assert w.params["mu0"]["value"] == cli["mu0"]["value"]


# The normal collisions without --fixed-gravity: 23 of 150 have two frames on a side, too few
# for free quadratics, and are skipped (the document lists them).
@pytest.mark.parametrize(
    "case, extra, n_skipped", [("normal", ["--fixed-gravity"], 0), ("oblique", [], 0), ("normal", [], 23)]
)
def test_kinematics_columns_equal_cli_json(in_root, case, extra, n_skipped):
    path = f"data/virtual/{case}/tracks.csv"
    doc = cli_json("kinematics", path, "--material", "nylon", *extra)
    result = rs.kinematics(path, "nylon", fixed_gravity=bool(extra))
    # The same document, bit for bit (both are the library's kinematics_json).
    assert result.to_dict() == doc
    assert doc["skipped"] == result.skipped and len(result.skipped) == n_skipped
    assert all("frames per phase = 2" in why for why in result.skipped)
    rows = doc["collisions"]
    cols = result.columns()
    shared = [k for k in rows[0] if k in cols]
    # The only CLI column not given as such: v_err_m_s, the rms of the eight velocity errors.
    assert set(rows[0]) - set(shared) == {"v_err_m_s"}
    for k in shared:
        assert list(cols[k]) == [r[k] for r in rows], k
    # The eight errors give the CLI's rms. Tolerance 1e-15 relative: numpy sums the eight
    # squares in another order than the CLI (each of the 8 additions and the square root rounds
    # once, 1.1e-16 each), so only the last bits may differ.
    errs = np.array([cols[k] for k in cols if k.startswith("v") and k.endswith("_err_m_s") and k != "v_n_err_m_s"])
    assert errs.shape[0] == 8
    rms = np.sqrt((errs**2).sum(axis=0) / 8)
    assert np.allclose(rms, [r["v_err_m_s"] for r in rows], rtol=1e-15, atol=0)
    assert all(result.sigma_pos_m == r["sigma_pos_m"] for r in rows)

"""The extension is built from the same dependency versions as the command line, and the
package documents itself."""

import sys
from pathlib import Path

import restitution as rs

ROOT = Path(__file__).resolve().parents[2]


def lock(path):
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        import pytest

        tomllib = pytest.importorskip("tomli")
    with open(path, "rb") as f:
        return {(p["name"], p["version"]) for p in tomllib.load(f)["package"]}


def test_python_lock_pins_the_roots_versions():
    # Identical numbers need identical code: every crate python/ shares with the root package is
    # locked at the root's version (refresh with: cp Cargo.lock python/ && cargo metadata
    # --manifest-path python/Cargo.toml).
    root, py = lock(ROOT / "Cargo.lock"), lock(ROOT / "python" / "Cargo.lock")
    root_names = {n for n, _ in root}
    shared = {(n, v) for n, v in py if n in root_names and n != "restitution"}
    assert shared <= root, sorted(shared - root)


def test_docstrings_and_exceptions():
    for f in (rs.predict, rs.e_of_kappa, rs.e_of_u, rs.fit, rs.walton_fit, rs.kinematics):
        assert f.__doc__ and "Raises" in f.__doc__, f.__name__
    assert issubclass(rs.InputError, ValueError)
    assert issubclass(rs.NumericalError, RuntimeError)
    assert rs.material_presets() == ["nylon", "steel", "glass", "aluminium"]

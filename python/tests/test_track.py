"""`restitution.track` against `restitution track`: the same library job on the same frames, so
the same JSON document, tracks.csv, summary and files; and the chain frames -> tracks ->
kinematics in memory."""

import json

import pytest

import restitution as rs
from conftest import run_cli


@pytest.fixture(scope="module")
def frames(tmp_path_factory):
    """Two collisions rendered by the release binary (`simulate --frames-out`, seeded)."""
    root = tmp_path_factory.mktemp("frames")
    run_cli("simulate", "--material", "nylon", "--out", root / "sim", "--n", "2", "--d-mm",
            "12.7", "--seed", "5", "--frames-out", root / "frames")
    return [root / "frames" / "c1", root / "frames" / "c2"]


def test_documents_equal_the_cli(frames, tmp_path):
    args = [*frames, "--fps", "1000", "--d-mm", "12.7"]
    cli_doc = json.loads(run_cli("track", *args, "--format", "json").stdout)
    cli_csv = run_cli("track", *args, "--format", "csv").stdout
    cli_table = run_cli("track", *args, "--out", tmp_path / "cli").stdout
    r = rs.track(frames, 1000, d_mm=12.7, out=tmp_path / "py")
    assert r.to_dict() == cli_doc
    assert r.tracks_csv == cli_csv
    assert r.text() == cli_table
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "py").iterdir())
    assert "overlay_c1.svg" in names and "tracks.csv" in names
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name


def test_the_chain_in_memory_equals_the_files(frames, tmp_path):
    r = rs.track(frames, 1000, d_mm=12.7, out=tmp_path)
    from_memory = rs.kinematics(r.tracks(), "nylon", fixed_gravity=True)
    from_file = rs.kinematics(tmp_path / "tracks.csv", "nylon", fixed_gravity=True)
    # The table is written as CSV text with every float in shortest round-trip form, so the
    # reader sees the same doubles: the same e, to the last bit.
    rows = from_file.to_dict()["collisions"]
    assert [c["e"] for c in from_memory.to_dict()["collisions"]] == [c["e"] for c in rows]
    assert len(rows) == 2


def test_a_single_directory_and_a_pixel_size(frames):
    r = rs.track(frames[0], 1000, pixel_m=2.5e-4)
    doc = r.to_dict()
    assert [c["collision"] for c in doc] == ["c1"]
    assert doc[0]["scale_from"] == "given" and doc[0]["pixel_m"] == 2.5e-4


@pytest.mark.parametrize(
    "kwargs,message",
    [
        (dict(fps=-1.0, d_mm=12.7), "fps -1: expected a positive number"),
        (dict(fps=1000.0), "the scale is missing: give pixel_m P"),
        (dict(fps=1000.0, d_mm=[1.0, 2.0, 3.0]), "d_mm takes one or two diameters"),
        (dict(fps=5e-324, d_mm=12.7), "fps 5e-324: expected 1e-6 to 10000000000 frames per second"),
        (dict(fps=1000.0, d_mm=12.7, pixel_m=float("inf")), "pixel_m inf: expected a positive number"),
    ],
)
def test_bad_arguments_name_the_keyword(frames, kwargs, message):
    with pytest.raises(rs.InputError) as err:
        rs.track(frames[0], **kwargs)
    assert str(err.value).startswith(message), str(err.value)


def test_a_missing_directory_gives_the_cli_message(tmp_path):
    missing = tmp_path / "nowhere"
    p = run_cli("track", missing, "--fps", "1000", "--d-mm", "12.7", check=False)
    assert p.returncode != 0
    cli_line = p.stderr.strip().removeprefix("restitution: error: ")
    with pytest.raises(rs.InputError) as err:
        rs.track(missing, 1000, d_mm=12.7)
    assert str(err.value) == cli_line

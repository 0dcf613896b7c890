"""The README's Python example runs as written, and the numbers its comments quote are the ones
it gives (so the README cannot drift from the package)."""

import re
import shutil
import warnings

from conftest import ROOT, run_cli


def readme_example() -> str:
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## From Python"):]
    block = section[section.index("```python\n") + len("```python\n"):]
    return block[: block.index("```")]


def test_the_readme_example_runs_and_its_comments_are_true(tmp_path, monkeypatch):
    shutil.copytree(ROOT / "data", tmp_path / "data")
    # The frames the example tracks, made by the command its comment gives.
    code = readme_example()
    command = re.search(r"# frames first: restitution (.*)", code).group(1).split()
    assert "--frames-out" in command
    monkeypatch.chdir(tmp_path)
    run_cli(*command, cwd=tmp_path)
    ns: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        exec(compile(code, "README.md (From Python)", "exec"), ns)
    r = ns["r"]
    assert r.preferred == re.search(r"r\.preferred\s+# '(\w+)'", code).group(1)
    # The comment's "value: 190.55.., stderr: 3.46.., interval: (183.78.., 197.34..)" are the
    # fit's numbers rounded to the digits shown.
    comment = re.search(r'r\.params\["min"\]\["eta"\]\s+# (.*)', code).group(1)
    quoted = [q.rstrip(".") for q in re.findall(r"\d[\d.]*\.\.", comment)]
    eta = r.params["min"]["eta"]
    actual = [eta["value"], eta["stderr"], *eta["interval"]]
    assert len(quoted) == 4
    for q, x in zip(quoted, actual):
        decimals = len(q.split(".")[1])
        assert round(x, decimals) == float(q), (q, x)
    assert (tmp_path / "lammps" / "in.restitution").exists()

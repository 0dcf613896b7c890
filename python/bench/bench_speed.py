"""Speed of the Python package against the same Rust calls without Python (the example
`python/examples/rust_baseline.rs`, run here with cargo).

    python python/bench/bench_speed.py [--n 1000000] [--repeats 20] [--out python/bench/speed.md]

Both sides take the minimum over `repeats` runs (the least disturbed run on a shared machine).
Measured: `e_of_kappa` on n values (numpy logspace(-4, 1, n), the master curve) against the
Rust loop over the same values; `fit` of data/fig7_nylon.csv (all five models, and vm alone)
against read + fit + JSON document in Rust. Ratios > 1 are the cost of the Python layer: the
copy of the input, the validation pass, the array conversion, the JSON parse of the document.
"""

import argparse
import json
import os
import platform
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import restitution as rs

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "data" / "fig7_nylon.csv"


def min_time(repeats, f):
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2]


def in_call_ratios(kappa, repeats):
    """Per call, total time of the Python function over the time of the Rust work inside it
    (measured by the extension itself), so machine load hits both parts of one call alike;
    the median over `repeats` calls."""
    ext = rs._models._ext
    inner = {}

    def timed(k, **kw):
        e, inner["s"] = ext.e_of_kappa_timed(k, **kw)
        return e

    loop = []
    original = ext.e_of_kappa
    ext.e_of_kappa = timed
    try:
        for _ in range(repeats):
            t = time.perf_counter()
            rs.e_of_kappa(kappa)
            loop.append((time.perf_counter() - t) / inner["s"])
    finally:
        ext.e_of_kappa = original
    fits = {}
    for model in ("all", "vm"):
        ratios = []
        for _ in range(repeats):
            t = time.perf_counter()
            r = rs.fit(str(DATA), "nylon", model=model)
            ratios.append((time.perf_counter() - t) / r._fitted.rust_seconds)
        fits[model] = median(ratios)
    return median(loop), fits["all"], fits["vm"]


def rust_baseline(n, repeats):
    cmd = [
        "cargo", "run", "--quiet", "--release", "--manifest-path", str(ROOT / "python" / "Cargo.toml"),
        "--example", "rust_baseline", "--", str(DATA), str(n), str(repeats),
    ]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=20)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()

    rust = rust_baseline(a.n, a.repeats)
    kappa = np.logspace(-4, 1, a.n)
    py_loop = min_time(a.repeats, lambda: rs.e_of_kappa(kappa)) / a.n * 1e9
    warnings.simplefilter("ignore", rs.DataWarning)
    py_all = min_time(a.repeats, lambda: rs.fit(str(DATA), "nylon")) * 1e3
    py_vm = min_time(a.repeats, lambda: rs.fit(str(DATA), "nylon", model="vm")) * 1e3

    inner = in_call_ratios(kappa, a.repeats)
    rows = [
        (f"e_of_kappa, {a.n} values (ns per value)", rust["e_of_kappa_ns"], py_loop, inner[0]),
        ("fit, all five models, 120 points (ms)", rust["fit_all_ms"], py_all, inner[1]),
        ("fit, vm only, 120 points (ms)", rust["fit_vm_ms"], py_vm, inner[2]),
    ]
    lines = [
        f"Speed of the Python package against the same Rust calls "
        f"(`python python/bench/bench_speed.py --n {a.n} --repeats {a.repeats}`; "
        f"minimum over {a.repeats} runs; {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} CPUs, Python {platform.python_version()}).",
        "",
        "| what | Rust example | Python | ratio | ratio within one call |",
        "| --- | --- | --- | --- | --- |",
    ]
    for what, r, p, q in rows:
        lines.append(f"| {what} | {r:.4g} | {p:.4g} | {p / r:.3f} | {q:.3f} |")
    lines += [
        "",
        "Rust example: `python/examples/rust_baseline.rs`, a separate process (minimum over the "
        "runs). Ratio within one call: the Python call's wall time over the time the extension "
        "spent in the library inside that same call (the loop alone; reading and fitting), "
        "median over the runs; robust to the load of a shared machine, which the ratio of two "
        "separate minima is not.",
    ]
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        a.out.write_text(text)


if __name__ == "__main__":
    sys.exit(main())

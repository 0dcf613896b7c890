"""Speed of the Python package against the same library calls in Rust without Python.

    python python/bench/bench_speed.py [--n 1000000] [--repeats 30] [--out python/bench/speed.md]

Three baselines, all the same library calls as the Python functions make:
* paired: the extension's `_bench_loop_seconds` / `_bench_fit_seconds` (the plain loop
  `restitution(kappa, Overlap, Master)` collected into a Vec; read + fit + JSON document) timed
  in Rust, alternated with the Python calls, so each pair shares the machine's load; the median
  of the per-pair ratios;
* within one call: the Python call's wall time over the time the extension itself spent in the
  library during that call (the loop; reading and fitting), median over the calls, and the
  difference in microseconds (for `fit` it includes rendering and parsing the JSON document);
* a separate process: the example `python/examples/rust_baseline.rs` (cargo run), minimum
  over its runs, against the minimum of the Python calls. On a loaded machine the two minima
  come from different moments, so this ratio is the least reliable of the three.

Measured: `e_of_kappa` on n values (numpy logspace(-4, 1, n), the master curve) and `fit` of
data/fig7_nylon.csv (all five models, and vm alone). A ratio above 1 is the cost of the Python
layer: argument handling, chunked copies of the input, the JSON parse of the document.
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
ext = rs._models._ext


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2]


def measure(repeats, python_call, rust_seconds):
    """Alternates the Python call (timed here, also returning the library time it reports)
    with the Rust baseline; returns (min Python s, min Rust s, median paired ratio, median
    within-call ratio)."""
    py, rust, paired, within, extra = [], [], [], [], []
    for _ in range(repeats):
        t = time.perf_counter()
        inner = python_call()
        p = time.perf_counter() - t
        r = rust_seconds()
        py.append(p)
        rust.append(r)
        paired.append(p / r)
        within.append(p / inner)
        extra.append(p - inner)
    return min(py), min(rust), median(paired), median(within), median(extra)


def kappa_call(kappa):
    inner = {}
    original = ext.e_of_kappa

    def timed(k, **kw):
        e, inner["s"] = ext.e_of_kappa_timed(k, **kw)
        return e

    def call():
        ext.e_of_kappa = timed
        try:
            rs.e_of_kappa(kappa)
        finally:
            ext.e_of_kappa = original
        return inner["s"]

    return call


def fit_call(model):
    def call():
        r = rs.fit(str(DATA), "nylon", model=model)
        r.params  # the document rendered and parsed: what a user reading the result pays
        return r._fitted.rust_seconds

    return call


def example(n, repeats):
    cmd = [
        "cargo", "run", "--quiet", "--release", "--manifest-path", str(ROOT / "python" / "Cargo.toml"),
        "--example", "rust_baseline", "--", str(DATA), str(n), str(repeats),
    ]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=30)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    warnings.simplefilter("ignore", rs.DataWarning)

    process = example(a.n, a.repeats)
    kappa = np.logspace(-4, 1, a.n)
    rows = [
        (f"e_of_kappa, {a.n} values (ns per value)", 1e9 / a.n, process["e_of_kappa_ns"],
         measure(a.repeats, kappa_call(kappa), lambda: ext._bench_loop_seconds(kappa))),
        ("fit, all five models, 120 points (ms)", 1e3, process["fit_all_ms"],
         measure(a.repeats, fit_call("all"), lambda: ext._bench_fit_seconds(str(DATA), "all"))),
        ("fit, vm only, 120 points (ms)", 1e3, process["fit_vm_ms"],
         measure(a.repeats, fit_call("vm"), lambda: ext._bench_fit_seconds(str(DATA), "vm"))),
    ]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines = [
        f"Python against the same Rust calls (`python python/bench/bench_speed.py --n {a.n} "
        f"--repeats {a.repeats}`; {platform.machine()}, {os.cpu_count()} CPUs, Python "
        f"{platform.python_version()}, load average {load:.1f} at the end).",
        "",
        "| what | Python (min) | Rust (min) | Python / Rust, paired (median) | within one call (median) | Python layer per call, us (median) | Rust example process (min) | ratio of minima to it |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for what, scale, proc_value, (py, rust, paired, within, extra) in rows:
        lines.append(
            f"| {what} | {py * scale:.4g} | {rust * scale:.4g} | {paired:.3f} | {within:.3f} "
            f"| {extra * 1e6:.0f} | {proc_value:.4g} | {py * scale / proc_value:.3f} |"
        )
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        a.out.write_text(text)


if __name__ == "__main__":
    sys.exit(main())

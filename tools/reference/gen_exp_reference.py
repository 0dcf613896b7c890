#!/usr/bin/env python3
"""High-precision reference values of exp(x), for the four-lane exp (src/fit/vexp.rs).

Arguments: 2000 seeded uniform doubles over [-708, 708] (the vector method's range), doubles at
and next to the ends of range-reduction intervals (k ln2 +- ln2/2, and the table method's
k ln2/128 +- ln2/256, where the reduced argument is largest) and a few round numbers. Each argument is written as the shortest decimal
that parses back to the same double, and exp of that double is computed by mpmath at 40 and at
60 digits; the two must agree to 1e-38 relative, and the 40-digit decimal must parse (Python's
float, correctly rounded like Rust's) to the double nearest the 60-digit value.

Writes tests/fixtures/exp_reference.csv (x,exp_x).
Usage: python3 tools/reference/gen_exp_reference.py   (deterministic; under a second)
"""

import math
import os
import random
import sys

from mpmath import mp, mpf

FIXTURES = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "fixtures")


def arguments():
    rng = random.Random(20240607)
    xs = [rng.uniform(-708.0, 708.0) for _ in range(2000)]
    ln2 = math.log(2.0)
    for k in list(range(-1020, 1021, 73)) + [-1, 0, 1]:
        for t in (k * ln2 + 0.5 * ln2, k * ln2 - 0.5 * ln2):
            if abs(t) < 707.9:
                xs += [t, math.nextafter(t, math.inf), math.nextafter(t, -math.inf)]
    # The table method's reduction intervals, k ln2/128 +- ln2/256: over the power law's [-8, 0]
    # and a few far out.
    for k in list(range(-1478, 1, 37)) + list(range(-130000, 130001, 9973)):
        for t in (k * ln2 / 128 + ln2 / 256, k * ln2 / 128 - ln2 / 256):
            if abs(t) < 707.9:
                xs += [t, math.nextafter(t, math.inf), math.nextafter(t, -math.inf)]
    xs += [0.0, 1.0, -1.0, 0.5, -0.5, ln2, 1e-10, -1e-10, 10.0, -10.0, 100.0, -100.0,
           700.0, -700.0, 707.9, -707.9]
    return xs


def main():
    rows = []
    bad = 0
    for x in arguments():
        mp.dps = 60
        hi = mp.exp(mpf(x))
        nearest = float(hi)
        mp.dps = 40
        lo = mp.exp(mpf(x))
        text = mp.nstr(lo, 40, min_fixed=1, max_fixed=0)
        mp.dps = 60
        if abs(mpf(text) / hi - 1) > mpf("1e-38") or float(text) != nearest:
            print(f"FAIL x={x!r}: {text} vs {hi}")
            bad += 1
        rows.append(f"{x!r},{text}")
    if bad:
        sys.exit(1)
    path = os.path.join(FIXTURES, "exp_reference.csv")
    with open(path, "w") as f:
        f.write("x,exp_x\n")
        f.write("\n".join(rows) + "\n")
    print(f"wrote {len(rows)} rows to {path}; checks passed")


if __name__ == "__main__":
    main()

"""100 000 rows of fit data in DIR, for scripts/time_big_fit.sh and scripts/compare_big_fit.sh:
repeated.csv, the Fig. 7 rows repeated (rows that share a pair geometry and a speed, merged
exactly by the fit), and distinct.csv, the same rows with every speed moved by up to 0.1%
(100 000 distinct points). Seeded, so every run writes the same files.

Usage: python3 scripts/big_fit_data.py DIR   (run from the repository's root)
"""
import random
import sys

d = sys.argv[1]
lines = [l for l in open("data/fig7_nylon.csv") if not l.startswith("#") and l.strip()]
head, rows = lines[0], lines[1:]
random.seed(1)
with open(f"{d}/repeated.csv", "w") as a, open(f"{d}/distinct.csv", "w") as b:
    a.write(head)
    b.write(head)
    for i in range(100_000):
        r = rows[i % len(rows)]
        a.write(r)
        f = r.rstrip("\n").split(",")
        f[1] = repr(float(f[1]) * (1 + random.uniform(-1e-3, 1e-3)))
        b.write(",".join(f) + "\n")

"""100 000 rows of fit data in DIR, for scripts/time_big_fit.sh and scripts/compare_big_fit.sh:
repeated.csv, the Fig. 7 rows repeated (rows that share a pair geometry and a speed, merged
exactly by the fit), and distinct.csv, the same rows with every speed moved by up to 0.1%
(100 000 distinct points), and sizes.csv: 100 000 rows each on its own pair of sizes
(d = 5 mm + i 1e-4 mm on d + 1 mm), speeds uniform in 0.5-5.5 m/s, e uniform in 0.88-0.90,
e_err 0.02 (no model's truth; sigma_y bounded from below only, and a kink of `min` per point
along it). Seeded, so every run writes the same files.

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
random.seed(2)
with open(f"{d}/sizes.csv", "w") as c:
    c.write("d_mm,d2_mm,v_n_m_s,e,e_err\n")
    for i in range(100_000):
        dm = 5 + i * 1e-4
        v = random.uniform(0.5, 5.5)
        e = random.uniform(0.88, 0.90)
        c.write(f"{dm!r},{dm + 1!r},{v!r},{e!r},0.02\n")

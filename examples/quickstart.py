"""The toolkit from Python, end to end: predict e(v), fit measured e(v_n), Walton's operator,
tracks to parameters and the fitted law as LAMMPS input. The numbers are the command line's (the package calls the same library).

    pip install ./python            # once, from the repository root (needs a Rust toolchain)
    python examples/quickstart.py [--out DIR]   # DIR: fig7.svg and the LAMMPS files (default: none)
"""

import argparse
import warnings
from pathlib import Path

import numpy as np

import restitution as rs

DATA = Path(__file__).resolve().parents[1] / "data"

ap = argparse.ArgumentParser(description="restitution from Python, end to end")
ap.add_argument("--out", type=Path, help="write fig7.svg of the fit and the LAMMPS files here")
args = ap.parse_args()

# 1. e(v) of the viscoelastic model for the paper's nylon, 25.4 mm spheres, eta = 190 kg/(s m)
#    (`restitution predict --model vm --material nylon --d-mm 25.4 --eta 190 --v-m-s ...`).
v = np.array([0.5, 2.0, 10.0, 40.0])
e, cols = rs.predict("vm", v, d_mm=25.4, material="nylon", eta=190.0, full_output=True)
print("vm, 25.4 mm nylon, eta = 190:")
for row in zip(v, e, cols["contact_time_s"], cols["max_force_n"]):
    print("  v = {:5.1f} m/s  e = {:.10f}  contact {:.3e} s  peak force {:8.2f} N".format(*row))

# The plastic model on a wall, and the universal curves on whole arrays (loops run in Rust).
e_wall = rs.predict("pm", v, d_mm=6.35, wall=True, material="nylon", sigma_y_pa=4e7)
print("pm, 6.35 mm nylon on a wall, sigma_y = 4e7 Pa:", np.round(e_wall, 6))
kappa = np.logspace(-4, 1, 1_000_000)
print("master curve over 1e6 values of kappa: e from", rs.e_of_kappa(kappa)[[0, -1]])

# 2. Fit the shipped Fig. 7-like data (`restitution fit data/fig7_nylon.csv --material nylon`).
#    The data have e > 1 in some rows (measurement error): kept, with a DataWarning.
with warnings.catch_warnings():
    warnings.simplefilter("ignore", rs.DataWarning)
    fit = rs.fit(DATA / "fig7_nylon.csv", "nylon")
print(f"\nfit: preferred model {fit.preferred}")
for name, p in fit.params[fit.preferred].items():
    lo, hi = p["interval"]
    print(f"  {name} = {p['value']:.5g} +- {p['stderr']:.2g} {p['unit']}, 95% [{lo:.5g}, {hi:.5g}]")
table = fit.table()  # a pandas DataFrame when pandas is installed, else a list of dicts
if isinstance(table, list):
    print("\n".join(map(str, table)))
else:
    print(table[["model", "param", "value", "stderr", "ci95_low", "ci95_high", "unit"]].to_string())
doc = fit.to_dict()  # exactly `restitution fit ... --format json`
print("chi2/dof of each model:", {f["model"]: round(f["reduced_chi2"], 3) for f in doc["fits"]})
if args.out:
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "fig7.svg").write_text(fit.fig7_svg())
    print("wrote", args.out / "fig7.svg")

# A table works as well as a file: a dict of arrays (or a pandas DataFrame) with the columns.
wall = rs.fit(
    {"d_mm": [12.7] * 5, "d2_mm": [np.inf] * 5, "v_n_m_s": [0.5, 1, 2, 4, 8],
     "e": [0.985, 0.979, 0.975, 0.968, 0.962], "e_err": [0.004] * 5},
    "nylon", model="vm",
)
print("\nvm fit of five drops on a wall: eta =", round(wall.params["vm"]["eta"]["value"], 1))

# 3. Walton's operator from oblique collisions (`restitution walton fit`).
w = rs.walton_fit(DATA / "oblique_collisions.csv", "nylon", bootstrap=200)
print("\nWalton:", {k: round(p["value"], 4) for k, p in w.params.items()}, "-", w.message)

# 4. From tracked centres to e, then to eta and sigma_y (`kinematics`, then `fit`).
k = rs.kinematics(DATA / "virtual" / "normal" / "tracks.csv", "nylon", fixed_gravity=True)
with warnings.catch_warnings():
    warnings.simplefilter("ignore", rs.DataWarning)  # e > 1 in a few noisy collisions: kept
    chain = rs.fit(k.fit_data(), "nylon", model="product")
p = chain.params["product"]
print(f"tracks -> e -> fit: eta = {p['eta']['value']:.0f}, sigma_y = {p['sigma_y']['value']:.3g} Pa"
      f" (planted 190 and 4e7)")

# 5. The fitted law for a simulation (`restitution export`): LAMMPS input for the scene's
#    sizes and speeds, with the closest law the engine can run and its largest deviation.
x = rs.export(fit, engine="lammps", v_range=(0.5, 40), tolerance=0.01, walton=w)
doc = x.to_dict()
print(f"\nexport for LAMMPS: {sorted(x.files)}; the files carry {doc['lammps']['note']};"
      f" the simplest law within 0.01 of the fit: {doc['recommendation']['chosen']}")
if args.out:
    args.out.mkdir(parents=True, exist_ok=True)
    for name, data in x.files.items():
        (args.out / name).write_bytes(data)

# Bad input is a ValueError with the command line's message.
try:
    rs.predict("vm", [1.0, -2.0], d_mm=25.4, material="nylon", eta=190.0)
except ValueError as err:
    print("\nValueError:", err)

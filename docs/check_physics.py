#!/usr/bin/env python3
"""Recomputes, independently of the Rust code, every number quoted in docs/physics.md.

Run from the repository root:  python3 docs/check_physics.py
Needs only python3 and mpmath (the same as tools/reference/). Each check asserts; the script
prints the numbers the document quotes and exits with status 1 if any assertion fails.
"""
import sys

from mpmath import beta, matrix, mp, mpf, pi, sqrt

mp.dps = 40
failures = []
# Exact exponents (mpf(0.2) would be the double nearest 0.2).
F1, F2, F3 = mpf(1) / 5, mpf(2) / 5, mpf(3) / 5


def check(name, got, want, tol):
    ok = abs(got - want) <= tol
    print(f"{'ok  ' if ok else 'FAIL'} {name}: {mp.nstr(got, 12)} (want {mp.nstr(want, 12)}, tol {tol})")
    if not ok:
        failures.append(name)


# ---------------------------------------------------------------- §6 the paper's nylon
Y, nu, rho = mpf("3.5e8"), mpf("0.3"), mpf(1140)
eta, sigma_y = mpf(190), mpf("4e7")
E = Y / (3 * (1 - nu**2))                 # the paper's modulus, text below Eq. (10)
E_star = 1 / (2 * (1 - nu**2) / Y)        # 1/E* = sum of (1 - nu^2)/Y, §1
check("E* = 3E/2", E_star, 3 * E / 2, mpf("1e-25"))
print("E =", mp.nstr(E, 8), "Pa;  E* =", mp.nstr(E_star, 8), "Pa")


def pair(d, wall=False):
    """(m, m_red, R~, K, C) of two identical spheres of diameter d, or of one on a wall."""
    m = pi / 6 * d**3 * rho
    r_eff, m_red = (d / 2, m) if wall else (d / 4, m / 2)
    K = mpf(4) / 3 * E_star * sqrt(r_eff)
    C = 4 * eta * sqrt(r_eff)
    return m, m_red, r_eff, K, C


def derived(d, wall=False):
    m, m_red, r_eff, K, C = pair(d, wall)
    delta_y = (pi * sigma_y / (2 * E_star)) ** 2 * r_eff
    W_y = mpf(2) / 5 * K * delta_y ** (mpf(5) / 2)
    V_Y = sqrt(2 * W_y / m_red)
    k, c = K / m_red, C / m_red
    T = lambda V: k ** (-F2) * V ** (-F1)
    kappa = lambda V: c * k ** (-F3) * V ** F1
    return dict(m=m, m_red=m_red, r_eff=r_eff, K=K, C=C, delta_y=delta_y, P_y=K * delta_y**1.5,
                W_y=W_y, V_Y=V_Y, T=T, kappa=kappa, A=2 * C / (3 * K), damp=4 * eta / m_red)


print("\nd_mm  geometry  m_kg  m_red_kg  K_N/m^1.5  delta_y_mm  P_y_N  V_Y_m/s  T(1 m/s)_s  "
      "kappa at 0.5, 2, 10, 40 m/s  LAMMPS damp = 4 eta/m_red")
for dmm in ["25.4", "12.7", "6.35"]:
    for wall in (False, True):
        q = derived(mpf(dmm) / 1000, wall)
        print(dmm, "wall" if wall else "pair", *(mp.nstr(q[k], 5) for k in ("m", "m_red", "K")),
              mp.nstr(q["delta_y"] * 1000, 4), mp.nstr(q["P_y"], 4), mp.nstr(q["V_Y"], 5),
              mp.nstr(q["T"](1), 5), [mp.nstr(q["kappa"](mpf(v)), 4) for v in ("0.5", "2", "10", "40")],
              mp.nstr(q["damp"], 5))

q = derived(mpf("0.0254"))
eq15 = sqrt(pi**4 * sigma_y**5 / (rho * E**4)) / (9 * sqrt(10))
check("V_Y from W_y = Eq. (15)", q["V_Y"], eq15, mpf("1e-30"))
check("V_Y = 6.3233 m/s (4 decimals)", q["V_Y"], mpf("6.3233"), mpf("5e-5"))
check("V_Y wall = 2 V_Y pair", derived(mpf("0.0254"), True)["V_Y"], 2 * q["V_Y"], mpf("1e-30"))
# General V_Y^2 = pi^5 sigma_y^5 R~^3 / (30 E*^4 m_red) (§3.1).
check("V_Y general closed form", sqrt(pi**5 * sigma_y**5 * q["r_eff"]**3 / (30 * E_star**4 * q["m_red"])),
      q["V_Y"], mpf("1e-30"))
check("sigma_y that would give 9 m/s", sigma_y * (9 / eq15) ** F2, mpf("4.6066e7"), mpf("1e3"))
check("A = 2 eta/E* (s)", q["A"], 2 * eta / E_star, mpf("1e-40"))
print("A =", mp.nstr(q["A"], 5), "s")
# kappa, identical spheres: 2 eta E^(-3/5) d^(1/5) m_red^(-2/5) V^(1/5) (§2.2).
d = mpf("0.0254")
check("kappa identical-sphere form", q["kappa"](2), 2 * eta * E**(-F3) * d**F1
      * q["m_red"]**(-F2) * 2**F1, mpf("1e-35"))
# kappa general: 4 (3/4)^(3/5) eta E*^(-3/5) R~^(1/5) m_red^(-2/5) V^(1/5).
check("kappa general form", q["kappa"](2), 4 * (mpf(3) / 4)**F3 * eta * E_star**(-F3)
      * q["r_eff"]**F1 * q["m_red"]**(-F2) * 2**F1, mpf("1e-35"))
check("kappa wall / kappa pair = 2^(-1/5)", derived(d, True)["kappa"](2) / q["kappa"](2),
      2**(-F1), mpf("1e-35"))

# ---------------------------------------------------------------- §2 constants
C1 = 2 * (mpf(5) / 4) ** (mpf(3) / 5) * mpf(2) / 5 * beta(mpf(3) / 5, mpf(3) / 2)
check("C1", C1, mpf("1.15344885809528879913"), mpf("1e-20"))
print("C2 = (3/5) C1^2 =", mp.nstr(mpf(3) / 5 * C1**2, 15))
tau = 2 * (mpf(5) / 4) ** (mpf(2) / 5) * mpf(2) / 5 * beta(mpf(2) / 5, mpf(1) / 2)
check("Hertz contact time tau_c", tau, mpf("3.2180654597190430845"), mpf("1e-19"))
print("x_max = (5/4)^(2/5) =", mp.nstr((mpf(5) / 4) ** (mpf(2) / 5), 12),
      " F_max = (5/4)^(3/5) =", mp.nstr((mpf(5) / 4) ** (mpf(3) / 5), 12),
      " tau_c (9/16)^(1/5) =", mp.nstr(tau * (mpf(9) / 16) ** (mpf(1) / 5), 6))
pref = C1 * (12 / pi) ** (mpf(2) / 5)
print("Eq. (11) corrected prefactor C1 (12/pi)^(2/5) =", mp.nstr(pref, 6))
check("C1 kappa = prefactor eta V^(1/5)/(E^(3/5) rho^(2/5) R)", C1 * q["kappa"](2),
      pref * eta * 2**F1 / (E**F3 * rho**F2 * d / 2), mpf("1e-35"))

# ---------------------------------------------------------------- §3 plastic closed form


def e_pm(u):
    w = sqrt(30 * u**2 - 5)
    q = 4 * (u**2 - 1) / (w + 5)
    return (1 + mpf(3) / 2 * q) / (u * (1 + q) ** (mpf(1) / 4)), q, w


def e_pm_work_balance(u):
    """e from the dimensional work balance of Eqs. (12)-(17), nylon 25.4 mm, no closed form."""
    p = derived(mpf("0.0254"))
    V = u * p["V_Y"]
    ke = p["m_red"] * V**2 / 2
    s_p = pi * sigma_y * p["r_eff"]
    X = 2 * (ke - p["W_y"]) / (p["P_y"] + sqrt(p["P_y"]**2 + 2 * s_p * (ke - p["W_y"])))
    P_star = p["P_y"] + s_p * X
    a_star = sqrt(p["r_eff"] * (p["delta_y"] + X))
    W_r = 3 * P_star**2 / (10 * E_star * a_star)
    return sqrt(W_r / ke)


for u in ["1.5", "2", "10", "1000"]:
    check(f"closed form = work balance at u = {u}", e_pm(mpf(u))[0], e_pm_work_balance(mpf(u)), mpf("1e-30"))
for u in ["1.01", "3"]:
    e, _, w = e_pm(mpf(u))
    check(f"e^4 = 21.6 w^4/((w^2+5)^2 (2w+5)) at u = {u}", e**4,
          mpf("21.6") * w**4 / ((w**2 + 5) ** 2 * (2 * w + 5)), mpf("1e-35"))
    check(f"1 - e^4 factorised at u = {u}", 1 - e**4,
          (w - 5) ** 2 * (2 * w**3 + mpf("3.4") * w**2 + 4 * w + 5) / ((w**2 + 5) ** 2 * (2 * w + 5)),
          mpf("1e-35"))
C_asym = sqrt(30) / 5 * (2 * sqrt(30) / 15) ** (-mpf(1) / 4)
check("asymptote C", C_asym, mpf("1.18499299221237"), mpf("1e-14"))
u = 1 + mpf("1e-10")
check("(1 - e)/(u - 1)^2 -> 6/25 at yield", (1 - e_pm(u)[0]) / (u - 1) ** 2, mpf(6) / 25, mpf("1e-8"))
check("e_pm(10/V_Y) for 6.35 mm, 10 m/s", e_pm(10 / q["V_Y"])[0], mpf("0.9645823466191602"), mpf("1e-15"))
check("e_pm(40/V_Y) for 6.35 mm, 40 m/s", e_pm(40 / q["V_Y"])[0], mpf("0.733124011659714"), mpf("1e-15"))

# ---------------------------------------------------------------- §5 slope of a fit at the window end


def slope_sd(N, u, degree):
    """sd of the fitted slope at t = N - 1 + u (frames t = 0..N-1, unit noise, unit frame time)."""
    X = matrix(N, degree + 1)
    for i in range(N):
        for j in range(degree + 1):
            X[i, j] = mpf(i) ** j
    cov = (X.T * X) ** -1
    t = N - 1 + u
    J = matrix([[0, 1, 2 * t]]) if degree == 2 else matrix([[0, 1]])
    return sqrt((J * cov * J.T)[0, 0])


print("\nN  Eq.(8) 1/sqrt(N)  quadratic slope at last frame / +0.5 / +1 frame  (ratios to Eq. 8)  linear slope")
for N in (3, 5, 8, 10, 12, 15, 20):
    e8 = 1 / sqrt(N)
    vals = [slope_sd(N, mpf(x), 2) for x in ("0", "0.5", "1")]
    print(N, mp.nstr(e8, 4), *(mp.nstr(v, 4) for v in vals), "|", *(mp.nstr(v / e8, 3) for v in vals),
          "|", mp.nstr(slope_sd(N, 0, 1), 4))
check("N = 10, half a frame past the end", slope_sd(10, mpf("0.5"), 2), mpf("0.4489043901713944"), mpf("1e-15"))
sub = mpf("0.048") / 192 / 4
print("paper camera: subpixel", sub, "m; n_s (25.4 mm) =", mp.nstr(mpf("0.0254") / sub, 5),
      "; Eq. (8) s = 2, N = 10:", mp.nstr(2 * sub / (mpf("1e-3") * sqrt(10)), 4), "m/s")

if failures:
    print("FAILED:", ", ".join(failures))
    sys.exit(1)
print("\nall checks passed")

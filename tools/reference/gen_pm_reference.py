#!/usr/bin/env python3
"""High-precision reference values for the plastic model (PM), docs/physics.md section 3.

Closed form, u = V / V_Y:
    e = 1                                   for u <= 1
    e = (1 + 1.5 q) / (u (1 + q)^(1/4))     for u > 1,
    q = 4 (u^2 - 1) / (sqrt(30 u^2 - 5) + 5)

Path A (closed form, mp.dps = 50).  For q <= 1, 1 - e is formed without cancellation: with
u^2 = 1 + (5/2) q + (15/8) q^2 (an identity of the definition of q) and
w = sqrt(1+q) - 1 - q/2 = -(q^2/4) / (sqrt(1+q) + 1 + q/2),
    1 - e^2 = (u^2 sqrt(1+q) - (1 + 1.5 q)^2) / (u^2 sqrt(1+q))
            = ((7/8) q^2 + (15/16) q^3 + u^2 w) / (u^2 sqrt(1+q)),
    1 - e   = (1 - e^2) / (1 + e).
(Near u = 1, 1 - e = (3/8) q^2 + ... is second order: about 2.4e-25 at u = 1 + 1e-12,
so the naive 1 - e at 50 digits would keep only ~25 digits of it.)  For q > 1 the
plain 1 - e has no cancellation and is used.  For u <= 30 both forms are computed
and compared (to the absolute ~1e-48 that the plain one can reach).

Path B (independent, dimensional, mp.dps = 90): identical nylon spheres
(Y = 3.5e8 Pa, nu = 0.3, rho = 1140 kg/m^3, sigma_y = 4e7 Pa, d = 25.4 mm),
E = Y/(3(1-nu^2)), R~ = d/4, E* = 3E/2, K = (4/3) E* sqrt(R~), m = (pi/6) d^3 rho,
m_red = m/2.  Yield overlap delta_y = (pi sigma_y/(2 E*))^2 R~, P_y = K delta_y^(3/2),
W_y = (2/5) K delta_y^(5/2) = (1/2) m_red V_Y^2.  For V = u V_Y the loading work
W_y + P_y D + (s/2) D^2 (D = delta* - delta_y, s = pi sigma_y R~) is set equal to
(1/2) m_red V^2 and solved for D with mpmath.findroot; P* = P_y + s D,
a*^2 = R~ delta*, W_r = 3 P*^2/(10 E* a*), e = sqrt(W_r / ((1/2) m_red V^2)),
1 - e taken directly (dps 90 leaves > 60 digits after the worst cancellation).
The two paths share no formula beyond the physics (Eqs. 12-17).

Checks (printed and asserted): path A == path B to 1e-25 relative in 1 - e and in e;
V_Y = 6.3233 m/s from the work balance and from Eq. 15
V_Y = (1/(9 sqrt 10)) sqrt(pi^4 sigma_y^5 / (rho E^4)) (the two agree to working
precision); s = (3/2) K delta_y^(1/2) (slope continuity); Hertz centre pressure at
yield 3 P_y / (2 pi a_y^2) = sigma_y; asymptote C = lim e u^(1/4)
= (sqrt30/5)(2 sqrt30/15)^(-1/4) = 1.18499299221237..., approached by e u^(1/4).

Writes tests/fixtures/pm_reference.csv (u,e,one_minus_e) and
tests/fixtures/pm_constants.csv (name,value).
Usage: python3 tools/reference/gen_pm_reference.py
"""

import os
import sys
import time

import mpmath
from mpmath import mp, mpf

U_VALUES = ["0.5", "1", "1+1e-12", "1+1e-9", "1+1e-6", "1+1e-3", "1.01", "1.1", "1.5", "2", "3",
            "5", "10", "30", "100", "1e3", "1e4", "1e6", "1e9", "1e12"]
# A dense grid as well, so that ulp bounds are checked between the round numbers: u - 1 from
# 1e-12 to 1 in steps of 10^(1/4), then u from 10^(1/8) to 1e12 in steps of 10^(1/8) (the
# printed double is the value used).
U_VALUES += [repr(1.0 + 10.0 ** (-k / 4)) for k in range(1, 48)]
U_VALUES += [repr(10.0 ** (k / 8)) for k in range(1, 97)]
# Large u, up to f64::MAX: around the Rust code's switch to the large-u form at u = 1e6 (the
# doubles on either side of it), where the closed form as written would overflow (1 + 1.5 q near
# u = 1.2e308; 30 u^2 near 3e153), and the largest double.
U_VALUES += ["999999.9999999999", "1000000.0000000001", "1e7", "1e8", "1e10", "1e15", "1e20",
             "1e50", "1e100", "1e153", "1e154", "1e200", "1e246", "1e300", "1e307",
             "1.2e308", "1.7976931348623157e308"]

DPS_A = 50
DPS_B = 90
OUT_DIGITS = 30

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
FIXTURES = os.path.join(REPO, "tests", "fixtures")


def u_double(spec):
    """The IEEE double for a u spec; '1+1e-12' means the double nearest to 1 + 1e-12
    (i.e. the result of the f64 addition 1.0 + 1e-12)."""
    if "+" in spec:
        a, b = spec.split("+")
        return float(a) + float(b)
    return float(spec)


def closed_form(u, force_series_form=False):
    """(e, 1-e) by the closed form.  For q <= 1 (e > 0.97) 1-e is formed by the
    cancellation-free expression; for q > 1 it is 1 - e directly (no cancellation
    there, while the q^2, q^3 terms of the other form would cancel).  u: mpf."""
    if u <= 1:
        return mpf(1), mpf(0)
    u2 = u * u
    q = 4 * (u2 - 1) / (mpmath.sqrt(30 * u2 - 5) + 5)
    sq = mpmath.sqrt(1 + q)
    e = (1 + mpf(3) / 2 * q) / (u * mpmath.sqrt(sq))
    w = -(q * q / 4) / (sq + 1 + q / 2)
    num = mpf(7) / 8 * q ** 2 + mpf(15) / 16 * q ** 3 + u2 * w
    one_m_e2 = num / (u2 * sq)
    if q <= 1 or force_series_form:
        return e, one_m_e2 / (1 + e)
    return e, 1 - e


class Nylon:
    def __init__(self):
        self.Y = mpf("3.5e8")
        self.nu = mpf("0.3")
        self.rho = mpf(1140)
        self.sigma_y = mpf("4e7")
        self.d = mpf("0.0254")
        self.E = self.Y / (3 * (1 - self.nu ** 2))
        self.R = self.d / 2
        self.Rt = self.d / 4
        self.Es = 3 * self.E / 2
        self.K = mpf(4) / 3 * self.Es * mpmath.sqrt(self.Rt)
        self.m = mpmath.pi / 6 * self.d ** 3 * self.rho
        self.m_red = self.m / 2
        self.delta_y = (mpmath.pi * self.sigma_y / (2 * self.Es)) ** 2 * self.Rt
        self.P_y = self.K * self.delta_y ** mpf(1.5)
        self.W_y = mpf(2) / 5 * self.K * self.delta_y ** mpf(2.5)
        self.s = mpmath.pi * self.sigma_y * self.Rt
        self.V_Y = mpmath.sqrt(2 * self.W_y / self.m_red)
        self.V_Y_eq15 = 1 / (9 * mpmath.sqrt(10)) * mpmath.sqrt(
            mpmath.pi ** 4 * self.sigma_y ** 5 / (self.rho * self.E ** 4))

    def restitution(self, u):
        """(e, 1-e) by the dimensional work balance, for V = u V_Y."""
        V = u * self.V_Y
        W_in = self.m_red * V ** 2 / 2
        if W_in <= self.W_y:
            return mpf(1), mpf(0)           # purely Hertzian: elastic, e = 1
        target = W_in - self.W_y

        def f(D):                            # normalised work residual
            return (self.P_y * D + self.s / 2 * D ** 2) / target - 1

        def df(D):
            return (self.P_y + self.s * D) / target

        # both estimates drop a positive term, so each over-estimates D; Newton on this
        # convex increasing function then converges monotonically from the right
        D0 = min(target / self.P_y, mpmath.sqrt(2 * target / self.s))
        D = mp.findroot(f, D0, df=df, solver="newton", tol=mpf(10) ** (-2 * mp.dps + 10), maxsteps=200)
        assert D > 0 and abs(f(D)) <= mpf(10) ** (-mp.dps + 5), f(D)
        delta_star = self.delta_y + D
        P_star = self.P_y + self.s * D
        a_star = mpmath.sqrt(self.Rt * delta_star)
        W_r = 3 * P_star ** 2 / (10 * self.Es * a_star)
        e = mpmath.sqrt(W_r / W_in)
        return e, 1 - e


def fmt(v, digits=OUT_DIGITS):
    return mpmath.nstr(v, digits, min_fixed=-5, max_fixed=8, strip_zeros=False).replace("E", "e")


def rel(a, b):
    if a == b:
        return mpf(0)
    return abs(a - b) / max(abs(a), abs(b))


def main():
    t0 = time.time()
    os.makedirs(FIXTURES, exist_ok=True)
    failures = []

    def check(cond, msg):
        print(("  PASS  " if cond else "  FAIL  ") + msg)
        if not cond:
            failures.append(msg)

    # ---------------- material constants (path B precision) ----------------
    mp.dps = DPS_B
    ny = Nylon()
    print("== Nylon, d = 25.4 mm (dps %d) ==" % mp.dps)
    print("  E = Y/(3(1-nu^2)) = %s Pa, E* = %s Pa, K = %s N/m^1.5" %
          (mpmath.nstr(ny.E, 15), mpmath.nstr(ny.Es, 15), mpmath.nstr(ny.K, 15)))
    print("  m_red = %s kg, delta_y = %s m, P_y = %s N, W_y = %s J" %
          (mpmath.nstr(ny.m_red, 15), mpmath.nstr(ny.delta_y, 15), mpmath.nstr(ny.P_y, 15),
           mpmath.nstr(ny.W_y, 15)))
    print("  V_Y (work balance) = %s m/s" % mpmath.nstr(ny.V_Y, 40))
    print("  V_Y (Eq. 15)       = %s m/s" % mpmath.nstr(ny.V_Y_eq15, 40))
    check(rel(ny.V_Y, ny.V_Y_eq15) < mpf(10) ** (-DPS_B + 5),
          "V_Y: work balance == Eq. 15 (rel %s)" % mpmath.nstr(rel(ny.V_Y, ny.V_Y_eq15), 3))
    check(mpmath.nstr(ny.V_Y, 5) == "6.3233", "V_Y = 6.3233 m/s (got %s)" % mpmath.nstr(ny.V_Y, 8))
    check(rel(ny.s, mpf(3) / 2 * ny.K * mpmath.sqrt(ny.delta_y)) < mpf(10) ** (-DPS_B + 5),
          "slope continuity s = pi sigma_y R~ = (3/2) K delta_y^(1/2)")
    a_y2 = ny.Rt * ny.delta_y
    check(rel(3 * ny.P_y / (2 * mpmath.pi * a_y2), ny.sigma_y) < mpf(10) ** (-DPS_B + 5),
          "Hertz centre pressure at yield 3 P_y/(2 pi a_y^2) = sigma_y")

    # ---------------- table ----------------
    rows = []
    worst_ome = mpf(0)
    worst_e = mpf(0)
    print("== e(u): closed form (dps %d) vs dimensional work balance (dps %d) ==" % (DPS_A, DPS_B))
    for spec in U_VALUES:
        ud = u_double(spec)
        u_str = repr(ud)
        assert float(u_str) == ud
        with mp.workdps(DPS_A):
            uA = mpf(ud)
            eA, omeA = closed_form(uA)
            if uA <= 30:
                # the two ways of forming 1 - e agree to the absolute accuracy of the naive one
                _, ome_cf = closed_form(uA, force_series_form=True)
                d_naive = abs((1 - eA) - ome_cf)
                check(d_naive <= mpf(10) ** (-DPS_A + 2),
                      "u=%s: cancellation-free 1-e vs naive 1-e at dps %d: |diff| %s"
                      % (u_str, DPS_A, mpmath.nstr(d_naive, 3)))
        with mp.workdps(DPS_B):
            uB = mpf(ud)
            eB, omeB = ny.restitution(uB)
            r1 = rel(omeA, omeB)
            r2 = rel(eA, eB)
            worst_ome = max(worst_ome, r1)
            worst_e = max(worst_e, r2)
            ok = r1 < mpf(10) ** -25 and r2 < mpf(10) ** -25
            print("  u=%-22s e=%s 1-e=%s  rel diff A/B: 1-e %s, e %s %s"
                  % (u_str, mpmath.nstr(eA, 22), mpmath.nstr(omeA, 12), mpmath.nstr(r1, 3),
                     mpmath.nstr(r2, 3), "ok" if ok else "FAIL"))
            if not ok:
                failures.append("A/B mismatch at u=%s" % u_str)
        rows.append((u_str, eA, omeA))
    with mp.workdps(DPS_B):
        check(worst_ome < mpf(10) ** -25 and worst_e < mpf(10) ** -25,
              "closed form == dimensional work balance: worst rel diff 1-e %s, e %s (< 1e-25)"
              % (mpmath.nstr(worst_ome, 3), mpmath.nstr(worst_e, 3)))

    # ---------------- asymptote ----------------
    mp.dps = DPS_A
    sqrt30 = mpmath.sqrt(30)
    C = sqrt30 / 5 * (2 * sqrt30 / 15) ** (-mpf(1) / 4)
    print("== Asymptote ==")
    print("  C = (sqrt30/5)(2 sqrt30/15)^(-1/4) = %s" % mpmath.nstr(C, 40))
    check(mpmath.nstr(C, 15) == "1.18499299221237", "C = 1.18499299221237...")
    prev = None
    for spec in ["1e3", "1e6", "1e9", "1e12"]:
        u = mpf(u_double(spec))
        e, _ = closed_form(u)
        dev = e * u ** (mpf(1) / 4) / C - 1
        print("  u=%-6s e u^(1/4) = %s   (e u^(1/4))/C - 1 = %s" %
              (spec, mpmath.nstr(e * u ** (mpf(1) / 4), 25), mpmath.nstr(dev, 6)))
        if prev is not None:
            check(abs(dev) < abs(prev), "e u^(1/4) -> C monotonically (u=%s)" % spec)
        prev = dev
    check(abs(prev) < mpf("1e-5"), "e u^(1/4) within 1e-5 of C at u = 1e12")
    # large-u series (Rust: plastic.rs): e u^(1/4)/C = 1 + a1/u + a2/u^2 + a3/u^3 + a4/u^4 + ...
    a = [-sqrt30 / 48, -mpf(23) / 768, -91 * sqrt30 / 36864, mpf(5035) / 1179648]
    # u^4 times the rest keeps about dps - 4 log10(u) digits: at dps 50 and u = 1e12 only two,
    # too few for the check (a4 came out 6% off); at dps 90 (path B's) still 42.
    for spec in ["1e6", "1e9", "1e12"]:
        with mp.workdps(DPS_B):
            r30 = mpmath.sqrt(30)
            C90 = r30 / 5 * (2 * r30 / 15) ** (-mpf(1) / 4)
            a90 = [-r30 / 48, -mpf(23) / 768, -91 * r30 / 36864, mpf(5035) / 1179648]
            u = mpf(u_double(spec))
            e, _ = closed_form(u)
            s3 = 1 + a90[0] / u + a90[1] / u ** 2 + a90[2] / u ** 3
            rest = (e * u ** (mpf(1) / 4) / C90 - s3) * u ** 4
        print("  u=%-6s (e u^(1/4)/C - (1 + a1/u + a2/u^2 + a3/u^3)) u^4 = %s (-> a4 = 5035/1179648 = %s)"
              % (spec, mpmath.nstr(rest, 12), mpmath.nstr(a[3], 12)))
        check(abs(rest / a90[3] - 1) < mpf(10) / u, "large-u series through u^-3 leaves a4/u^4 at u=%s" % spec)
    u = mpf(u_double("1e6"))
    e, _ = closed_form(u)
    s3 = C * u ** (-mpf(1) / 4) * (1 + a[0] / u + a[1] / u ** 2 + a[2] / u ** 3)
    check(rel(s3, e) < mpf("1e-26"), "four-term large-u form at the switch u = 1e6: rel error %s (< 1e-26)"
          % mpmath.nstr(rel(s3, e), 3))
    # near u = 1: 1 - e = (3/8) q^2 (1 + O(q))
    u = mpf(u_double("1+1e-9"))
    q = 4 * (u * u - 1) / (mpmath.sqrt(30 * u * u - 5) + 5)
    _, ome = closed_form(u)
    print("  near u = 1: (1-e)/q^2 at u = 1+1e-9: %s (-> 3/8)" % mpmath.nstr(ome / q ** 2, 15))
    check(abs(ome / q ** 2 - mpf(3) / 8) < 1e-6, "(1 - e) ~ (3/8) q^2 as u -> 1+")

    # ---------------- VM constants for pm_constants.csv ----------------
    hertz_tau = 2 * (mpf(5) / 4) ** (mpf(2) / 5) * (mpf(2) / 5) * mpmath.beta(mpf(2) / 5, mpf(1) / 2)
    c1 = 2 * (mpf(5) / 4) ** (mpf(3) / 5) * (mpf(2) / 5) * mpmath.beta(mpf(3) / 5, mpf(3) / 2)
    c2 = mpf(3) / 5 * c1 ** 2
    check(mpmath.nstr(hertz_tau, 20) == "3.2180654597190430845", "hertz_tau = 3.2180654597190430845")
    check(mpmath.nstr(c1, 21) == "1.15344885809528879913", "c1 = 1.15344885809528879913")

    path = os.path.join(FIXTURES, "pm_reference.csv")
    with open(path, "w") as f:
        f.write("u,e,one_minus_e\n")
        for u_str, e, ome in rows:
            f.write("%s,%s,%s\n" % (u_str, fmt(e), fmt(ome) if ome != 0 else "0"))
    print("wrote %s" % os.path.relpath(path, REPO))

    path = os.path.join(FIXTURES, "pm_constants.csv")
    with open(path, "w") as f:
        f.write("name,value\n")
        with mp.workdps(DPS_B):
            f.write("v_yield_nylon_m_s,%s\n" % fmt(ny.V_Y))
        f.write("asymptote_c,%s\n" % fmt(C))
        f.write("hertz_tau,%s\n" % fmt(hertz_tau))
        f.write("c1,%s\n" % fmt(c1))
        f.write("c2,%s\n" % fmt(c2))
    print("wrote %s" % os.path.relpath(path, REPO))

    print("total runtime %.1f s" % (time.time() - t0))
    if failures:
        print("FAILED CHECKS:")
        for m in failures:
            print("  " + m)
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()

//! The plastic model against independent values: the mpmath closed form at 50 digits, itself
//! checked against the dimensional work balance at 90 digits (tests/fixtures/pm_reference.csv).

use proptest::prelude::*;
use restitution::contact::{Material, Pair, Sphere};
use restitution::models::plastic::{self, Plastic, rebound_u};

fn rows() -> Vec<(f64, f64, f64)> {
    include_str!("fixtures/pm_reference.csv")
        .lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (f[0], f[1], f[2])
        })
        .collect()
}

fn ulps(got: f64, want: f64) -> f64 {
    if got == want {
        return 0.0;
    }
    ((got - want) / want).abs() / f64::EPSILON
}

#[test]
fn closed_form_is_accurate_to_a_few_ulp_from_yield_to_f64_max() {
    // Target: relative error of e <= 4 ulp. 1 - e is computed separately (it goes down to
    // 2.4e-25 at u = 1 + 1e-12, where 1 - e taken as 1 - e would be 0) through a
    // cancellation-free chain of about ten roundings, so its bar is 8 ulp (measured: 4.4).
    // The fixture runs to u = f64::MAX, across the switch to the large-u form at u = 1e6 (the
    // doubles either side of it are rows), where the closed form as written would overflow.
    let rows = rows();
    assert!(rows.iter().any(|r| r.0 == f64::MAX) && rows.iter().any(|r| r.0 == 999999.9999999999));
    let mut worst = (0.0f64, 0.0f64);
    for (u, e, ome) in rows {
        let r = rebound_u(u);
        assert!(
            ulps(r.e, e) <= 4.0,
            "u={u}: e {} vs {e} ({} ulp)",
            r.e,
            ulps(r.e, e)
        );
        if ome == 0.0 {
            assert_eq!(r.one_minus_e, 0.0);
        } else {
            assert!(
                ulps(r.one_minus_e, ome) <= 8.0,
                "u={u}: 1-e {} vs {ome} ({} ulp)",
                r.one_minus_e,
                ulps(r.one_minus_e, ome)
            );
        }
        if u >= plastic::U_ASYMPTOTE {
            worst.0 = worst.0.max(ulps(r.e, e));
        } else {
            worst.1 = worst.1.max(ulps(r.e, e));
        }
    }
    eprintln!(
        "max ulp of e: large-u form {}, closed form {}",
        worst.0, worst.1
    );
}

#[test]
fn switch_to_the_large_u_form_is_seamless() {
    // Either side of u = 1e6 the two forms agree to rounding (the large-u form's truncation
    // error there is 4.3e-27, far below it): at most 4 ulp apart, and e keeps decreasing.
    let below = rebound_u(999999.9999999999).e;
    let at = rebound_u(1e6).e;
    let above = rebound_u(1000000.0000000001).e;
    assert!(
        ulps(below, at) <= 4.0 && ulps(above, at) <= 4.0,
        "{below} {at} {above}"
    );
    assert!(below >= at && at >= above);
}

#[test]
fn every_finite_u_gives_a_number() {
    // u up to f64::MAX: e positive and finite, 1 - e in (0, 1]; u = +inf gives the limit e = 0.
    let mut u: f64 = 1.0 + 1e-15;
    while u.is_finite() {
        let r = rebound_u(u);
        assert!(r.e > 0.0 && r.e <= 1.0 && r.e.is_finite(), "u={u}: {r:?}");
        assert!(r.one_minus_e >= 0.0 && r.one_minus_e <= 1.0, "u={u}: {r:?}");
        u *= 1.37;
    }
    let r = rebound_u(f64::MAX);
    assert!(r.e > 1e-77 && r.one_minus_e == 1.0, "{r:?}");
    assert_eq!(rebound_u(f64::INFINITY).e, 0.0);
    assert!(plastic::try_rebound_u(f64::INFINITY).is_err());
    assert!(plastic::try_rebound_u(f64::NAN).is_err());
    assert!(plastic::try_rebound_u(-1.0).is_err());
}

#[test]
fn yield_speed_out_of_range_is_an_error_naming_sigma_y() {
    // sigma_y = 1e-130 Pa: V_Y ~ sigma_y^(5/2) ~ 1e-345 m/s, below the smallest double. It used to
    // be 0, making every u infinite and e print as 1 ("fully elastic") where the truth is e -> 0.
    let nylon = Material::preset("nylon").unwrap();
    let c = Pair::identical(Sphere::new(0.0254, nylon).unwrap()).contact();
    let err = Plastic::new(c, 1e-130).unwrap_err().to_string();
    assert!(
        err.contains("V_Y") && err.contains("underflow") && err.contains("sigma_y = 1e-130 Pa"),
        "{err}"
    );
    // sigma_y = 1e-100 Pa: V_Y ~ 1e-270 m/s is representable, although delta_y^(5/2) (1e-545)
    // is not: computed by the exact sigma_y -> 4^j sigma_y scaling, V_Y ~ sigma_y^(5/2) exactly.
    let small = c.try_yield_velocity_m_s(1e-100).unwrap();
    let ref_ = c.yield_velocity_m_s(4e7);
    // (1e-100/4e7)^(5/2) = 1e-270/(4e7)^2.5; relative 1e-13 covers the powf roundings.
    let want = ref_ * (1e-100f64 / 4e7).powf(2.5);
    assert!((small / want - 1.0).abs() < 1e-13, "{small} vs {want}");
    // A huge sigma_y overflows V_Y: an error, not inf.
    let err = c.try_yield_velocity_m_s(1e200).unwrap_err().to_string();
    assert!(
        err.contains("overflow") && err.contains("sigma_y = 1e200 Pa"),
        "{err}"
    );
    // Huge Young's modulus: E* is finite, V_Y tiny but fine or an error, never 0.
    let stiff = Material::new(1e300, 0.3, 1000.0).unwrap();
    let cs = Pair::identical(Sphere::new(0.01, stiff).unwrap()).contact();
    match cs.try_yield_velocity_m_s(4e7) {
        Ok(v) => assert!(v >= f64::MIN_POSITIVE, "{v}"),
        Err(e) => assert!(e.to_string().contains("underflow"), "{e}"),
    }
}

#[test]
fn derived_contact_quantities_are_checked() {
    let nylon = Material::preset("nylon").unwrap();
    // A 1e-110 m sphere has mass (pi/6) d^3 rho = 6e-328 kg: 0 in f64.
    let tiny = Pair::identical(Sphere::new(1e-110, nylon).unwrap());
    let err = tiny.try_contact().unwrap_err().to_string();
    assert!(
        err.contains("m_red") && err.contains("d = 1e-110 m"),
        "{err}"
    );
    // A subnormal modulus makes the compliance infinite and E* = 0.
    let soft = Material::new(1e-310, 0.3, 1000.0).unwrap();
    let err = Pair::identical(Sphere::new(0.01, soft).unwrap())
        .try_contact()
        .unwrap_err()
        .to_string();
    assert!(err.contains("E*") && err.contains("Y = 1e-310 Pa"), "{err}");
    let ok = Pair::identical(Sphere::new(0.0254, nylon).unwrap())
        .try_contact()
        .unwrap();
    assert!(ok.try_kappa(190.0, 2.0).unwrap() > 0.0);
    assert_eq!(ok.try_kappa(0.0, 2.0).unwrap(), 0.0);
    let err = ok.try_kappa(1e308, 1e300).unwrap_err().to_string();
    assert!(
        err.contains("kappa") && err.contains("eta = 1e308"),
        "{err}"
    );
    assert!(ok.try_kappa(f64::NAN, 2.0).is_err());
}

#[test]
fn naive_q_fails_near_yield() {
    // The textbook q = -2/3 + (2/15) sqrt(30u^2 - 5) loses the digits of 1 - e as u -> 1:
    // at u = 1 + 1e-6 it is off by far more than 4 ulp (this is why the closed form is rewritten).
    let (u, _, ome) = rows().into_iter().find(|r| r.0 == 1.000001).unwrap();
    let naive = plastic::rebound_u_naive(u);
    assert!(ulps(naive.one_minus_e, ome) > 1e6);
}

#[test]
fn yield_velocity_and_asymptote_constants() {
    let nylon = Material::preset("nylon").unwrap();
    let c = Pair::identical(Sphere::new(0.0254, nylon).unwrap()).contact();
    let p = Plastic::new(c, 4.0e7).unwrap();
    // docs/physics.md §3: 6.3233 m/s (mpmath: 6.32330301672985722766).
    assert!((p.yield_velocity_m_s() / 6.32330301672985722766 - 1.0).abs() < 1e-14);
    assert!((plastic::asymptote_c() / 1.18499299221237150870 - 1.0).abs() < 1e-15);
}

#[test]
fn closed_form_matches_the_dimensional_work_balance() {
    // Two different routes to e (Eqs. 12-17 dimensionally vs the closed form in u): they
    // agree to rounding of the dimensional route, whose cancellation near yield costs digits:
    // 1e-12 relative in e for u >= 1.1.
    let nylon = Material::preset("nylon").unwrap();
    for (d_mm, d2) in [(25.4, Some(12.7)), (6.35, None)] {
        let s = Sphere::new(d_mm * 1e-3, nylon).unwrap();
        let pair = match d2 {
            Some(d2) => Pair::unequal(s, Sphere::new(d2 * 1e-3, nylon).unwrap()),
            None => Pair::on_wall(s, nylon),
        };
        let p = Plastic::new(pair.contact(), 4.0e7).unwrap();
        let vy = p.yield_velocity_m_s();
        for u in [0.5, 1.1, 2.0, 10.0, 1e3, 1e6] {
            let v = u * vy;
            let closed = p.rebound(v).unwrap().e;
            let work = p.rebound_by_work_balance(v).unwrap();
            assert!(
                (closed / work - 1.0).abs() < 1e-12,
                "{d_mm} u={u}: {closed} vs {work}"
            );
        }
    }
}

#[test]
fn bad_inputs_are_errors() {
    let nylon = Material::preset("nylon").unwrap();
    let c = Pair::identical(Sphere::new(0.0254, nylon).unwrap()).contact();
    assert!(Plastic::new(c, 0.0).is_err());
    assert!(Plastic::new(c, f64::NAN).is_err());
    let p = Plastic::new(c, 4e7).unwrap();
    assert!(p.rebound(-1.0).is_err());
    assert!(p.rebound(f64::INFINITY).is_err());
    assert!(rebound_u(f64::NAN).e.is_nan());
}

proptest! {
    #[test]
    fn e_is_in_range_and_decreasing(log_u in -1.0f64..308.0, step in 1.0001f64..2.0) {
        let u = 10f64.powf(log_u);
        prop_assume!((u * step).is_finite());
        let a = rebound_u(u);
        let b = rebound_u(u * step);
        prop_assert!(a.e > 0.0 && a.e <= 1.0);
        prop_assert!(b.e <= a.e);
        // e (<= 4 ulp) and 1 - e (<= 8 ulp) are computed separately: their sum is 1 to ~8 eps.
        prop_assert!((a.e + a.one_minus_e - 1.0).abs() <= 8.0 * f64::EPSILON);
        if u > 1.0 { prop_assert!(b.e < a.e); }
    }
}

use super::*;

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        ((a - b) / b).abs()
    }
}

/// Cody's erf against mpmath 1.3 (50 digits, rounded to f64).
#[test]
fn erf_erfc_erfcx_match_known_values() {
    let erf_values = [
        (1e-300, 1.128_379_167_095_512_6e-300),
        (1e-10, 1.128_379_167_095_512_6e-10),
        (0.1, 0.112_462_916_018_284_9),
        (0.25, 0.276_326_390_168_236_96),
        (0.468_75, 0.492_613_473_217_937_97),
        (0.5, 0.520_499_877_813_046_5),
        (1.0, 0.842_700_792_949_714_9),
        (2.0, 0.995_322_265_018_952_7),
        (3.9, 0.999_999_965_207_751_4),
        (6.0, 1.0),
        (10.0, 1.0),
    ];
    for (x, want) in erf_values {
        assert!(rel(erf(x), want) < 4e-16, "erf({x}) = {} vs {want}", erf(x));
        assert!(rel(erf(-x), -want) < 4e-16, "erf(-{x})");
    }
    let erfc_values = [
        (0.5, 0.479_500_122_186_953_5),
        (1.0, 0.157_299_207_050_285_13),
        (2.0, 0.004_677_734_981_047_266),
        (3.9, 3.479_224_859_723_176_5e-8),
        (4.5, 1.966_160_441_542_887_6e-10),
        (10.0, 2.088_487_583_762_545e-45),
        (26.0, 5.663_192_408_856_143e-296),
    ];
    for (x, want) in erfc_values {
        let got = exp_neg_sq(x) * erfcx(x);
        assert!(rel(got, want) < 6e-16, "erfc({x}) = {got} vs {want}");
    }
    let erfcx_values = [
        (0.5, 0.615_690_344_192_925_9),
        (1.0, 0.427_583_576_155_807),
        (3.0, 0.179_001_151_181_389_96),
        (4.5, 0.122_484_804_273_841_42),
        (20.0, 0.028_174_348_741_051_32),
        (1e5, 5.641_895_835_195_468_5e-6),
        (1e8, 5.641_895_835_477_562e-9),
    ];
    for (x, want) in erfcx_values {
        assert!(
            rel(erfcx(x), want) < 4e-16,
            "erfcx({x}) = {} vs {want}",
            erfcx(x)
        );
    }
}

#[test]
fn one_minus_sq_is_exact_where_it_cancels() {
    // b = 1 - 2^-30, v = 2^-20: 1 - b^2 - v^2 = 2^-29 - 2^-60 - 2^-40, representable,
    // while b^2 itself is not (it needs 61 bits).
    let b = 1.0 - 2f64.powi(-30);
    let v = 2f64.powi(-20);
    assert_eq!(
        one_minus_sq(b, v),
        2f64.powi(-29) - 2f64.powi(-40) - 2f64.powi(-60)
    );
    // v an ulp-sized distance inside the end of that chord: g = 2 h a to rounding.
    let h = one_minus_sq(b, 0.0).sqrt();
    let g = one_minus_sq(b, h);
    assert!(g.abs() < 4.0 * f64::EPSILON * h * h, "{g}");
    assert_eq!(one_minus_sq(0.0, 0.5), 0.75);
    assert_eq!(one_minus_sq(0.5, 0.5), 0.5);
}

#[test]
fn sinh_minus_x_series_meets_the_direct_difference() {
    for x in [2.0f64, 1.5, 1.0, 0.5, 0.1, 1e-3, 1e-8, -0.7] {
        let direct = x.sinh() - x;
        // The direct difference loses ~x^2/6 relative digits: trust it where that is small.
        let tol = 4.0 * f64::EPSILON * x.sinh().abs() / direct.abs().max(1e-300);
        let series = sinh_minus_x(x);
        assert!(
            rel(series, direct) <= tol.max(1e-15),
            "{x}: {series} vs {direct}"
        );
    }
    // Where the direct difference is all rounding: x^3/6 (1 + x^2/20), the rest < 1e-25.
    assert!(rel(sinh_minus_x(1e-6), 1e-18 / 6.0 * (1.0 + 1e-12 / 20.0)) < 1e-15);
}

/// The two linear forms agree where they meet (both accurate there), and the gaussian's
/// three one-sided forms agree across their boundaries.
#[test]
fn forms_agree_at_their_switches() {
    for b in [0.0, 0.3, 0.7] {
        let c = chord(b);
        // v where 1 - u = 1/4: u = 3/4.
        let vs = (0.5625f64 - b * b).sqrt();
        for (v0, v1) in [
            (vs, c.h),
            (vs, vs + 1e-3),
            (vs + 1e-9, vs + 0.1 * (c.h - vs)),
        ] {
            let (s, k) = (c.linear_surface(v0, v1, false), c.linear_bulk(v0, v1));
            assert!(rel(s, k) < 2e-15, "b {b} [{v0}, {v1}]: {s} vs {k}");
        }
    }
    // The gaussian's one-sided forms near the boundaries between them, where each is
    // still accurate: the short form at 2 m d = 0.35 (against both erf forms) and at
    // d = 0.25 (against the erf form), the erf and erfc forms at x0 = 0.5.
    for b in [0.0, 0.2, 0.6] {
        let c = chord(b);
        for s in [0.05, 1.0 / 3.0, 1.0] {
            let k = std::f64::consts::FRAC_1_SQRT_2 / s;
            let at = |x0: f64, x1: f64| (x0 / k, x1 / k);
            let short = |c: &Chord, s, v0, v1| c.gaussian_short(s, v0, v1, v1 - v0, false);
            let erfc = |c: &Chord, s, v0, v1| c.gaussian_erfc(s, v0, v1, false);
            let erf = |c: &Chord, s, v0, v1| c.gaussian_erf(s, v0, v1);
            let check = |(v0, v1): (f64, f64), forms: &[&Form]| {
                if v1 > c.h {
                    return;
                }
                let want = forms[0](&c, s, v0, v1);
                for form in &forms[1..] {
                    let got = form(&c, s, v0, v1);
                    assert!(
                        rel(got, want) < 1e-14,
                        "b {b} s {s} [{v0}, {v1}]: {got} vs {want}"
                    );
                }
            };
            // 2 m d = x1^2 - x0^2 = 0.35 just above x0 = 0.5, and around x0 = 1.
            check(at(0.5, (0.25f64 + 0.35).sqrt()), &[&short, &erfc, &erf]);
            check(at(1.0, (1.0f64 + 0.35).sqrt()), &[&short, &erfc, &erf]);
            // d = 0.25 near the centre.
            check(at(0.0, 0.5), &[&short, &erf]);
            check(at(0.05, 0.55), &[&short, &erf]);
            // x0 = 0.5, far pieces.
            check(at(0.5, 1.5), &[&erfc, &erf]);
            check(at(0.5, 3.0), &[&erfc, &erf]);
        }
    }
}

/// A one-sided form of the gaussian profile: `(chord, s, v0, v1) -> J`.
type Form = dyn Fn(&Chord, f64, f64, f64) -> f64;

fn chord(b: f64) -> Chord {
    let h2 = one_minus_sq(b, 0.0);
    Chord {
        b,
        h: h2.sqrt(),
        h2,
    }
}

//! Chords through the centre, grazing lines, pieces near the chord end, tiny pieces, diameters, clipping and profile names.

use super::*;

/// `beta = 0` (and a 3D ray through the centre): closed values for dyadic pieces, where the
/// linear profile's `asinh` term vanishes, and the reference for random pieces (its kink at
/// `v = 0` is a breakpoint).
#[test]
fn lines_through_the_centre() {
    // integral of 1, 1 - |v|, 1 - v^2 over [-0.5, 0.75] and [0.25, 0.75]: exact in f64 or
    // within an ulp.
    let exact = [
        (Profile::Constant, -0.5, 0.75, 1.25),
        (Profile::Linear, -0.5, 0.75, 1.25 - (0.25 + 0.5625) / 2.0),
        (Profile::Linear, 0.25, 0.75, 0.5 - (0.5625 - 0.0625) / 2.0),
        (Profile::Linear, -1.0, 1.0, 1.0),
        (Profile::Quadratic, -0.5, 0.75, 1.25 - 0.546_875 / 3.0),
        (Profile::Quadratic, 0.25, 0.75, 0.5 - 0.406_25 / 3.0),
        (Profile::Quadratic, -1.0, 1.0, 4.0 / 3.0),
    ];
    for (p, v0, v1, want) in exact {
        let got = p.line_integral(0.0, v0, v1);
        assert!(
            rel(got, want) <= 2.5e-16,
            "{} [{v0}, {v1}]: {got} vs {want}",
            label(p)
        );
    }
    let mut rng = Rng::new(0x5eed_0003);
    let mut worst = Worst::default();
    for i in 0..300 {
        let (x, y) = (rng.range(-1.1, 1.1), rng.range(-1.1, 1.1));
        let (v0, v1) = (x.min(y), x.max(y));
        for p in PROFILES {
            worst.add(
                &format!("{} / beta 0", label(p)),
                rel(p.line_integral(0.0, v0, v1), reference(p, 0.0, v0, v1)),
                || format!("piece {i}: {v0} .. {v1}"),
            );
        }
    }
    worst.check(TOL);
    // A world ray through the centre of a sphere of radius 2: the whole chord is 2 r I_f.
    let (c, r) = (DVec3::new(1.0, -2.0, 3.0), 2.0);
    for p in PROFILES {
        let got = p.ray_integral(c - 5.0 * DVec3::Z, DVec3::Z, 0.0, f64::INFINITY, c, r);
        assert!(rel(got, 2.0 * r * p.integral()) < 1e-15, "{}", label(p));
    }
}

/// Grazing lines, `beta = 1 - 1e-12` (half chord 1.4e-6: every value of f is ~1e-12 or,
/// for the gaussian, `exp(-1 / (2 s^2))`), and `1 - 1e-15`, `1 - 2^-40`: whole chords, halves
/// and pieces, against the reference; and the quadratic's whole chord `4 h^3 / 3` exactly.
#[test]
fn grazing_lines() {
    let mut worst = Worst::default();
    for b in [1.0 - 1e-12, 1.0 - 1e-15, 1.0 - 2f64.powi(-40)] {
        let h = half_chord(b);
        let pieces = [
            (-1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 0.0),
            (-0.5 * h, 0.3 * h),
            (0.2 * h, 0.7 * h),
            (0.999 * h, 2.0),
            ((1.0 - 1e-6) * h, 2.0),
            (-h, -(1.0 - 1e-9) * h),
            ((1.0 - 1e-3) * h, (1.0 - 1e-4) * h),
        ];
        for (v0, v1) in pieces {
            for p in PROFILES {
                worst.add(
                    &format!("{} / grazing", label(p)),
                    rel(p.line_integral(b, v0, v1), reference(p, b, v0, v1)),
                    || format!("beta {b}, [{v0:e}, {v1:e}]"),
                );
            }
        }
        // (1 - b)(1 + b) is exact here (Sterbenz and an exact product for these b), so h^2 is.
        let h2 = (1.0 - b) * (1.0 + b);
        let want = 4.0 / 3.0 * h2 * h2.sqrt();
        let got = Profile::Quadratic.line_integral(b, -1.0, 1.0);
        assert!(rel(got, want) < 1e-15, "beta {b}: {got} vs {want}");
    }
    worst.check(TOL);
}

/// Pieces a few ulps to a million ulps of `h` from the chord end, up to it or between two
/// such points, on either side: there `g = 1 - u^2` falls to 1e-23, and the distance to the
/// end must come from the exact `1 - b^2 - v^2` (or the closed forms lose all digits).
#[test]
fn pieces_within_ulps_of_the_chord_end() {
    let mut worst = Worst::default();
    for b in [0.5, 0.9, 1.0 - 1e-8, 1.0 - 1e-12, 1.0 - 2f64.powi(-40)] {
        let h = half_chord(b);
        let ulp = h * f64::EPSILON;
        for k in [3.0, 10.0, 1e3, 1e6] {
            let v0 = h - k * ulp;
            for (lo, hi) in [(v0, 2.0), (v0, h - 0.5 * k * ulp), (-2.0, -v0)] {
                for p in PROFILES {
                    let want = reference(p, b, lo, hi);
                    worst.add(
                        &format!("{} / ulps from the end", label(p)),
                        rel(p.line_integral(b, lo, hi), want),
                        || format!("beta {b}, [{lo:e}, {hi:e}]"),
                    );
                }
            }
        }
    }
    worst.check(TOL);
}

/// The narrowest gaussian on pieces ending at the chord end, for lines whose rounded half
/// chord `fl(h)` is furthest from the exact one: `f` falls by `exp(-200)` over the radius,
/// so an end taken at `fl(h)` instead of the exact end moves the result by up to 2e-14
/// (`h |fl(h) - h| / s^2`). Pieces just long enough for the `erfc` form, where the end's
/// term is nearly as large as the start's, and short pieces (the Hermite form), to 4e-15.
#[test]
fn narrow_gaussian_keeps_the_chord_end_exact() {
    let p = Profile::Gaussian { width: 0.05 };
    // Lines with |fl(h) - h| near half an ulp: g(fl(h)) = (h - fl(h)) (h + fl(h)) exactly.
    let mut lines: Vec<(f64, f64)> = (400..1000)
        .map(|k| {
            let b = k as f64 / 1000.0;
            let h = half_chord(b);
            (b, (one_minus_u2(b, h) / (2.0 * h * h * f64::EPSILON)).abs())
        })
        .collect();
    lines.sort_by(|x, y| y.1.total_cmp(&x.1));
    let mut worst = Worst::default();
    for &(b, off) in &lines[..12] {
        assert!(off > 0.2, "beta {b}: fl(h) is {off} ulp-ish off only");
        let h = half_chord(b);
        // 2 m d = h L / (2 s^2): 0.4 (the erfc form, end term e^-0.8 of the start's) and 0.004.
        for len in [0.4 * 2.0 * 0.0025 / h, 0.004 * 2.0 * 0.0025 / h] {
            for (v0, v1) in [(h - len, 2.0), (-2.0, len - h)] {
                let want = reference(p, b, v0, v1);
                worst.add(
                    &format!("{} / at the end", label(p)),
                    rel(p.line_integral(b, v0, v1), want),
                    || format!("beta {b}, [{v0:e}, {v1:e}]"),
                );
            }
        }
    }
    worst.check(4e-15);
}

/// Pieces of 2^-40 (9.1e-13) of the radius: the closed form against the midpoint rule,
/// `J = L f(m) - L^3 f''(xi) / 24`, with `f(m)` from the exact `g` and a bound on `|f''|`
/// per profile; at the centre, half way, near the chord end and on grazing lines.
#[test]
fn tiny_pieces_match_the_midpoint_rule() {
    let len = 2f64.powi(-40);
    let mut worst = Worst::default();
    for b in [0.0, 0.3, 0.9, 1.0 - 1e-6, 1.0 - 1e-12] {
        let h = half_chord(b);
        for frac in [0.0, 0.5, -0.5, 0.999, 1.0 - 1e-6, -(1.0 - 1e-6)] {
            // Midpoints on a 2^-41 grid, so that m -+ len/2 and (v0 + v1) / 2 = m are exact.
            let grid = 2f64.powi(41);
            let m = (frac * h * grid).round() / grid;
            let (v0, v1) = (m - 0.5 * len, m + 0.5 * len);
            if v1 >= h || v0 <= -h || (b == 0.0 && m == 0.0) {
                continue; // off the chord, or the linear profile's kink (below)
            }
            let g = one_minus_u2(b, m);
            let u_min = (b * b + (m.abs() - len).max(0.0).powi(2)).sqrt();
            for p in PROFILES {
                let fm = shape(p, b, m, g);
                let f2 = match p {
                    Profile::Constant => 0.0,
                    Profile::Quadratic => 2.0,
                    Profile::Linear => b * b / u_min.powi(3),
                    Profile::Gaussian { width: s } => {
                        // |f''| = f |v^2 / s^4 - 1 / s^2|, f within 1e-9 of f(m) over the piece.
                        2.0 * fm * (h * h / s.powi(4) + 1.0 / (s * s))
                    }
                };
                let mid = len * fm;
                let bound = len.powi(3) / 24.0 * f2;
                let err = ((p.line_integral(b, v0, v1) - mid).abs() - bound).max(0.0) / mid;
                worst.add(&format!("{} / tiny", label(p)), err, || {
                    format!("beta {b}, m {m:e}")
                });
            }
        }
    }
    worst.check(TOL);
    // Through the centre the linear profile's kink: integral of 1 - |v| = L - L^2 / 4.
    let got = Profile::Linear.line_integral(0.0, -0.5 * len, 0.5 * len);
    assert!(rel(got, len - len * len / 4.0) < 2.5e-16, "{got}");
}

/// The whole diameter is `2 I_f`, and `I_f` is the integral of `f` over `[0, 1]`: 1, 1/2,
/// 2/3, and for the gaussian the quadrature of `exp(-u^2 / (2 s^2))`.
#[test]
fn diameter_is_twice_the_profile_integral() {
    assert_eq!(Profile::Constant.integral(), 1.0);
    assert_eq!(Profile::Linear.integral(), 0.5);
    assert_eq!(Profile::Quadratic.integral(), 2.0 / 3.0);
    for p in PROFILES {
        let i_f = p.integral();
        let quad = integrate(&|u| p.f(u), 0.0, 1.0, (0.0, 0.0));
        assert!(rel(i_f, quad) < 1e-14, "{}: {i_f} vs {quad}", label(p));
        let d = p.line_integral(0.0, -1.0, 1.0);
        assert!(
            rel(d, 2.0 * i_f) < 1e-15,
            "{}: {d} vs {}",
            label(p),
            2.0 * i_f
        );
    }
}

/// `sigma0` keeps `transparency` the transmittance along a diameter: `exp(-sigma0 2 r I_f)`
/// and `exp(-sigma0 * ray_integral)` along a world diameter equal it to 1e-14 for
/// transparencies 1e-6 to 1 - 1e-12 (optical depths 1e-12 to 14; below that, `exp` itself
/// turns the last ulp of the depth into `depth * eps` relative). For depths from 1e-12 to 1e4
/// the diameter's optical depth `sigma0 r J` equals `-ln(transparency)` to 1e-14.
#[test]
fn diameter_transmittance_is_the_transparency() {
    let mut rng = Rng::new(0x5eed_0004);
    for p in PROFILES {
        for t in [1.0 - 1e-12, 1.0 - 1e-6, 0.9, 0.5, 0.1, 1e-3, 1e-6] {
            for r in [1e-3, 0.7, 1e3] {
                let s0 = sigma0(t, r, p);
                let tr = (-s0 * 2.0 * r * p.integral()).exp();
                assert!(rel(tr, t) < 1e-14, "{} T {t} r {r}: {tr}", label(p));
                let c = DVec3::new(rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), 0.0) * r;
                let w = unit(&mut rng);
                let len = p.ray_integral(c - 3.0 * r * w, w, 0.0, f64::INFINITY, c, r);
                let tr = (-s0 * len).exp();
                assert!(rel(tr, t) < 1e-14, "{} T {t} r {r}: ray {tr}", label(p));
            }
        }
        for depth in [1e-12f64, 1e-6, 1.0, 1e2, 700.0] {
            let t = (-depth).exp();
            let tau = sigma0(t, 2.5, p) * 2.5 * p.line_integral(0.0, -1.0, 1.0);
            assert!(
                rel(tau, -t.ln()) < 1e-14,
                "{} depth {depth}: {tau}",
                label(p)
            );
        }
        // Depths beyond exp's range: sigma0 from -ln(T) = 1e4 written out.
        let s0 = 1e4 / (2.0 * 2.5 * p.integral());
        let tau = s0 * 2.5 * p.line_integral(0.0, -1.0, 1.0);
        assert!(rel(tau, 1e4) < 1e-14, "{}: {tau}", label(p));
    }
    // The constant profile's sigma0 is docs/model.md section 1's -ln(T) / (2 r), bit for bit.
    assert_eq!(
        sigma0(0.3, 1.7, Profile::Constant),
        -(0.3f64.ln()) / (2.0 * 1.7)
    );
}

/// Clipping and edge cases: empty, reversed and outside pieces, lines that miss, NaN; and
/// additivity, `J(v0, v1) = J(v0, vm) + J(vm, v1)`, over random splits (it catches a piece
/// folded to the wrong side or a wrong branch on either side of a switch).
#[test]
fn clipping_empty_pieces_and_additivity() {
    for p in PROFILES {
        assert_eq!(p.line_integral(0.5, 0.3, 0.3), 0.0);
        assert_eq!(p.line_integral(0.5, 0.4, 0.3), 0.0);
        assert_eq!(p.line_integral(0.5, 0.9, 2.0), 0.0); // past the half chord 0.866
        assert_eq!(p.line_integral(0.5, -3.0, -0.9), 0.0);
        assert_eq!(p.line_integral(1.0, -1.0, 1.0), 0.0);
        assert_eq!(p.line_integral(1.5, -1.0, 1.0), 0.0);
        assert!(p.line_integral(f64::NAN, -1.0, 1.0).is_nan());
        assert!(p.line_integral(0.5, f64::NAN, 1.0).is_nan());
        assert_eq!(
            p.line_integral(-0.5, -0.2, 0.6),
            p.line_integral(0.5, -0.2, 0.6),
            "beta is a distance"
        );
        assert_eq!(
            p.line_integral(0.5, f64::NEG_INFINITY, f64::INFINITY),
            p.line_integral(0.5, -1.0, 1.0)
        );
        // A ray that misses, and a piece of a ray before the sphere.
        let (c, r) = (DVec3::new(0.0, 0.0, 0.0), 1.0);
        let o = DVec3::new(1.2, 0.0, -5.0);
        assert_eq!(p.ray_integral(o, DVec3::Z, 0.0, 10.0, c, r), 0.0);
        let o = DVec3::new(0.2, 0.0, -5.0);
        assert_eq!(p.ray_integral(o, DVec3::Z, 0.0, 4.0, c, r), 0.0);
        assert!(p.ray_integral(o, DVec3::Z, 0.0, 4.5, c, r) > 0.0);
    }
    let mut rng = Rng::new(0x5eed_0005);
    let mut worst = Worst::default();
    for i in 0..3000 {
        let b = match i % 3 {
            0 => rng.f(),
            1 => 1.0 - rng.log10(-14.0, -1.0),
            _ => rng.log10(-12.0, 0.0),
        };
        let h = half_chord(b);
        let mut v = [rng.range(-1.1, 1.1) * h, rng.range(-1.1, 1.1) * h, 0.0];
        v[2] = if i % 2 == 0 {
            rng.range(-1.1, 1.1) * h
        } else {
            -v[0]
        };
        v.sort_by(f64::total_cmp);
        for p in PROFILES {
            let whole = p.line_integral(b, v[0], v[2]);
            let parts = p.line_integral(b, v[0], v[1]) + p.line_integral(b, v[1], v[2]);
            if whole > 0.0 {
                worst.add(
                    &format!("{} / additivity", label(p)),
                    rel(parts, whole),
                    || format!("beta {b:e}, {v:?}"),
                );
            }
        }
    }
    worst.check(TOL);
}

/// Names and widths, and the messages of the refusals.
#[test]
fn parse_names_widths_and_errors() {
    for p in [Profile::Constant, Profile::Linear, Profile::Quadratic] {
        assert_eq!(Profile::parse(p.name(), None), Ok(p));
    }
    assert_eq!(
        Profile::parse("gaussian", None),
        Ok(Profile::Gaussian {
            width: DEFAULT_WIDTH
        })
    );
    assert_eq!(DEFAULT_WIDTH, 1.0 / 3.0);
    for width in [0.05, 1.0 / 3.0, 1.0, 1e-300] {
        let p = Profile::parse("gaussian", Some(width)).unwrap();
        assert_eq!(p, Profile::Gaussian { width });
        assert_eq!(p.name(), "gaussian");
    }
    for width in [0.0, -0.1, 1.0 + f64::EPSILON, 2.0, f64::INFINITY, f64::NAN] {
        let e = Profile::parse("gaussian", Some(width)).unwrap_err();
        assert!(matches!(e, ProfileError::Width(w) if w.to_bits() == width.to_bits()));
    }
    assert_eq!(
        Profile::parse("gaussian", Some(0.0))
            .unwrap_err()
            .to_string(),
        "gaussian width 0 is outside (0, 1] (in units of the sphere's radius)"
    );
    assert_eq!(
        Profile::parse("Gaussian", None).unwrap_err().to_string(),
        "unknown density profile `Gaussian` (expected constant, linear, quadratic or gaussian)"
    );
    assert_eq!(
        Profile::parse("", None),
        Err(ProfileError::UnknownName(String::new()))
    );
    assert_eq!(
        Profile::parse("linear", Some(0.5)).unwrap_err().to_string(),
        "the linear profile takes no width (only gaussian has one)"
    );
    // f is 0 outside the ball.
    for p in PROFILES {
        assert_eq!(p.f(1.000_000_1), 0.0);
        assert_eq!(p.f(-0.1), 0.0);
        assert!(p.f(f64::NAN).is_nan());
        assert!(p.f(1.0) >= 0.0);
        assert_eq!(p.f(0.0), 1.0);
    }
    assert_eq!(Profile::Linear.f(1.0), 0.0);
    assert_eq!(Profile::Quadratic.f(1.0), 0.0);
    assert_eq!(Profile::Linear.f(0.25), 0.75);
    assert_eq!(Profile::Quadratic.f(0.5), 0.75);
}

use super::*;

#[test]
fn counts_in_exponent_form() {
    assert_eq!(parse_count("1e6"), Ok(1_000_000));
    assert_eq!(parse_count("1000"), Ok(1000));
    assert!(parse_count("1.5").is_err() && parse_count("0").is_err());
}

#[test]
fn reported_errors_against_true_ones() {
    let reference = [[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0], [2.0; 3]];
    let img = [
        [1.1, 1.0, 1.0],
        [1.0, 0.9, 1.02],
        [0.0, 0.0, 0.0],
        [2.0, 2.0, 2.4],
    ];
    // Reported 0.2 (covers 0.1), 0.05 (not 0.1), 0 on an exact pixel, 0.2 (not 0.4).
    let reported = [0.2, 0.05, 0.0, 0.2];
    let (frac, med) = error_coverage(&img, &reported, &reference);
    assert_eq!(frac, 0.5);
    // Ratios 2, 0.5, 0.5: the median is 0.5 (up to f32 rounding of the reports).
    assert!((med - 0.5).abs() < 1e-6, "{med}");
}

#[test]
fn march_projection_follows_the_observed_orders() {
    // Error ~ h, time ~ 1/h: from (0.2, 1e-2, 1 s) and (0.05, 2.5e-3, 4 s), 1e-5 needs
    // h = 2e-4 and 1000 s.
    let p = march_projection(&[(0.2, 1e-2, 1.0), (0.05, 2.5e-3, 4.0)], 1e-5).unwrap();
    assert!(
        (p.step - 2e-4).abs() < 1e-15 && (p.seconds - 1000.0).abs() < 1e-9,
        "{p:?}"
    );
    assert!(p.extrapolated);
    // Fixed costs at coarse steps (time growing slower than 1/h) still project as 1/h.
    let p = march_projection(&[(0.2, 1e-2, 1.0), (0.05, 2.5e-3, 1.5)], 1e-5).unwrap();
    assert!((p.seconds - 375.0).abs() < 1e-9, "{p:?}");
    // An error that does not shrink gives no projection.
    assert_eq!(
        march_projection(&[(0.2, 1e-2, 1.0), (0.05, 1e-2, 4.0)], 1e-5),
        None
    );
    assert_eq!(march_projection(&[(0.2, 1e-2, 1.0)], 1e-5), None);
}

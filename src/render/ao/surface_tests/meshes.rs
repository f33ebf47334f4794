//! Exact AO among the triangles of meshes: shared edges counted once, and points on a
//! triangle seeing their neighbours.

use super::*;

/// A flat square as 2 triangles, and a strip bent along its shared edges, seen from points
/// where neighbours lie side by side and where one hides behind another.
#[test]
fn tessellated_surfaces_count_their_shared_edges_once() {
    let mut rng = Mix(25);
    let (mut worst_square, mut worst_strip) = (0.0f64, 0.0f64);
    // The square and its two halves (both diagonals, both windings).
    let q = [
        DVec3::new(-0.7, -0.4, 1.0),
        DVec3::new(0.9, -0.6, 1.3),
        DVec3::new(1.1, 0.8, 1.1),
        DVec3::new(-0.5, 1.0, 0.8),
    ];
    for case in 0..40 {
        let x = DVec3::new(rng.next() - 0.5, rng.next() - 0.5, 0.4 * rng.next() - 0.2);
        let n = (DVec3::Z + rng.unit() * 0.8).normalize();
        let reach = [f64::INFINITY, 1.3][case % 2];
        let halves = match case % 4 {
            0 => vec![vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]],
            1 => vec![vec![q[1], q[2], q[3]], vec![q[1], q[3], q[0]]],
            2 => vec![vec![q[0], q[1], q[2]], vec![q[3], q[2], q[0]]],
            _ => vec![vec![q[2], q[1], q[0]], vec![q[3], q[0], q[2]]],
        };
        for w in both() {
            let whole = exact_polys(&[q.to_vec()], x, n, reach, w);
            let split = exact_polys(&halves, x, n, reach, w);
            worst_square = worst_square.max((whole - split).abs());
            assert!(
                (whole - split).abs() <= 1e-13,
                "case {case} {w:?}: the square {whole}, its halves {split}"
            );
            if reach.is_infinite() {
                let rel: Vec<DVec3> = q.iter().map(|p| *p - x).collect();
                let (cosine, uniform) = closed_forms(&rel, n);
                let want = if w == Weighting::Cosine {
                    cosine
                } else {
                    uniform
                };
                assert!((whole - want).abs() <= 1e-13, "{whole} against {want}");
            }
        }
    }
    // A strip of 8 triangles folded at its edges (a zigzag), seen from points in front of,
    // beside and behind it, so that some neighbours lie behind others.
    let strip: Vec<DVec3> = (0..10)
        .map(|i| {
            let f = i as f64;
            DVec3::new(
                0.5 * f - 2.0,
                if i % 2 == 0 { -0.6 } else { 0.6 },
                0.5 * (f * 1.3).sin(),
            )
        })
        .collect();
    let triangles: Vec<[DVec3; 3]> = (0..8)
        .map(|i| {
            // Alternating windings, as a strip's triangles come.
            if i % 2 == 0 {
                [strip[i], strip[i + 1], strip[i + 2]]
            } else {
                [strip[i + 1], strip[i], strip[i + 2]]
            }
        })
        .collect();
    let occ = Occluders {
        triangles: triangles.clone(),
        ..Occluders::default()
    };
    let prep = occ.prepared();
    let mut s = AoScratch::default();
    let mut points = 0;
    for case in 0..60 {
        let x = DVec3::new(
            3.0 * rng.next() - 1.5,
            2.0 * rng.next() - 1.0,
            2.5 * rng.next() - 1.25,
        ) + DVec3::new(0.0, 0.0, if case % 3 == 0 { 2.0 } else { 0.0 });
        let n = rng.unit();
        let reach = [f64::INFINITY, 1.5, 0.8][case % 3];
        for w in both() {
            let got = 1.0 - unoccluded(&prep, x, n, None, (reach, w), &mut s);
            let (want, unconverged) = occ.reference(x, n, On::Nothing, reach, w);
            assert_eq!(unconverged, 0);
            worst_strip = worst_strip.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-12,
                "strip point {case} at {x} reach {reach} {w:?}: {got} against {want}"
            );
            points += 1;
        }
    }
    assert_eq!(points, 120);
    eprintln!(
        "tessellated: worst {worst_square:e} square against its halves, {worst_strip:e} \
         strip against the reference"
    );
}

/// Points on the floor (two triangles) near a sphere resting above it, and a triangle
/// standing at a concave crease: each against its closed form.
#[test]
fn a_point_on_a_triangle_sees_its_neighbours() {
    let floor = [
        [
            DVec3::new(-5.0, -5.0, 0.0),
            DVec3::new(5.0, -5.0, 0.0),
            DVec3::new(5.0, 5.0, 0.0),
        ],
        [
            DVec3::new(-5.0, -5.0, 0.0),
            DVec3::new(5.0, 5.0, 0.0),
            DVec3::new(-5.0, 5.0, 0.0),
        ],
    ];
    let wall = [
        DVec3::new(-1.0, 2.0, 0.0),
        DVec3::new(1.0, 2.0, 0.0),
        DVec3::new(0.0, 2.5, 1.5),
    ];
    let ball = (DVec3::new(0.3, -0.2, 1.2), 1.0);
    let occ = Occluders {
        spheres: vec![ball],
        triangles: vec![floor[0], floor[1], wall],
        ..Occluders::default()
    };
    let prep = occ.prepared();
    let mut s = AoScratch::default();
    let mut rng = Mix(26);
    let mut worst = 0.0f64;
    for k in 0..200 {
        // On either half of the floor (the seam included), away from the wall's foot.
        let x = DVec3::new(4.0 * rng.next() - 2.0, 3.0 * rng.next() - 2.5, 0.0);
        let x = if k == 0 {
            DVec3::new(0.25, 0.25, 0.0)
        } else {
            x
        };
        let on = if x.x >= x.y { 0 } else { 1 };
        let own = occ.own(&prep, On::Triangle(on));
        for w in both() {
            let got = 1.0 - unoccluded(&prep, x, DVec3::Z, own, (f64::INFINITY, w), &mut s);
            // The sphere's cap and the wall's triangle: apart or not, against the reference;
            // where the wall is below the horizon or hidden, the cap alone.
            let (want, unconverged) =
                occ.reference(x, DVec3::Z, On::Triangle(on), f64::INFINITY, w);
            assert_eq!(unconverged, 0);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-12,
                "floor point {x} {w:?}: {got} against {want}"
            );
        }
        // Cosine-weighted with the wall and the ball apart, the sum of their closed forms.
        let Blocked::Cap(cap) = blocked_by_ball(x, ball.0, ball.1, f64::INFINITY) else {
            panic!("a cap")
        };
        let rel: Vec<DVec3> = wall.iter().map(|p| *p - x).collect();
        let wall_ff = closed_forms(&rel, DVec3::Z).0;
        let cap_ff = one_cap(cap.axis.z, cap.axis.truncate().length(), cap.cos);
        let apart = {
            let mut r = Regions::default();
            blocked_by_polygon(x, DVec3::Z, &wall, f64::INFINITY, &mut r);
            let b = r.bound(0);
            b.axis.dot(cap.axis).acos() > b.angle + cap.cos.acos()
        };
        if apart {
            let got = 1.0
                - unoccluded(
                    &prep,
                    x,
                    DVec3::Z,
                    own,
                    (f64::INFINITY, Weighting::Cosine),
                    &mut s,
                );
            worst = worst.max((got - (wall_ff + cap_ff)).abs());
            assert!((got - (wall_ff + cap_ff)).abs() <= 1e-13, "{x}: {got}");
        }
    }
    // On the wall, facing the floor's side: the floor rises in front of it (a concave crease
    // at its foot) and the ball stands beside it.
    let g = (wall[1] - wall[0]).cross(wall[2] - wall[0]).normalize();
    let g = if g.y > 0.0 { -g } else { g };
    for k in 0..40 {
        let (a, b) = (rng.next(), rng.next());
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let x = wall[0] + (wall[1] - wall[0]) * a + (wall[2] - wall[0]) * b;
        for w in both() {
            let own = occ.own(&prep, On::Triangle(2));
            let got = 1.0 - unoccluded(&prep, x, g, own, (f64::INFINITY, w), &mut s);
            let (want, unconverged) = occ.reference(x, g, On::Triangle(2), f64::INFINITY, w);
            assert_eq!(unconverged, 0);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-12,
                "wall point {k} {w:?}: {got} against {want}"
            );
        }
    }
    eprintln!("points on triangles: worst {worst:e}");
}

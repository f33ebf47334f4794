//! `gtsphere convert particles.csv -o out.wrl`: every table dialect, each bad-input error, and
//! the round trip table -> VRML -> scene IR (values compared with the table's own numbers).

use glam::DVec3;
use gtsphere::particles::ColumnSpec;
use gtsphere::particles::{convert, ColorScale, Delimiter, Extras, TableOptions, WriteOptions};
use gtsphere::scene::Scene;
use gtsphere::vrml::{load_str, LoadOptions};
use proptest::prelude::*;

const FRAMED: WriteOptions = WriteOptions {
    plain: false,
    extras: Extras {
        viewpoint: true,
        lights: true,
    },
};

/// Converts `table` in memory and reads the VRML back; the VRML text too.
fn convert_with(
    table: &str,
    opts: TableOptions,
    w: WriteOptions,
) -> Result<(Scene, String), String> {
    let input: Box<dyn std::io::Read> = Box::new(std::io::Cursor::new(table.as_bytes().to_vec()));
    let (out, _) = convert("t.csv", input, Vec::new(), opts, w).map_err(|e| e.to_string())?;
    let text = String::from_utf8(out).expect("utf8");
    let (scene, report) = load_str("out.wrl", &text, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("the output does not read back:\n{e}\n{text}"));
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    Ok((scene, text))
}

fn ir(table: &str) -> Scene {
    convert_with(table, TableOptions::default(), FRAMED)
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

fn ir_with(table: &str, opts: TableOptions) -> Scene {
    convert_with(table, opts, FRAMED)
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

fn err(table: &str, opts: TableOptions) -> String {
    match convert_with(table, opts, FRAMED) {
        Ok((_, text)) => panic!("expected an error, got:\n{text}"),
        Err(e) => e,
    }
}

fn columns(spec: &[&str]) -> ColumnSpec {
    ColumnSpec::parse(&spec.iter().map(|s| s.to_string()).collect::<Vec<_>>()).unwrap()
}

fn centres(s: &Scene) -> Vec<[f64; 4]> {
    s.spheres
        .iter()
        .map(|p| [p.center.x, p.center.y, p.center.z, p.radius])
        .collect()
}

fn diffuse(s: &Scene, k: usize) -> DVec3 {
    s.material_of(&s.spheres[k]).diffuse
}

#[test]
fn comma_header_with_byte_colours() {
    let s = ir("id,x,y,z,radius,red,green,blue\n1,0,0,0,1,255,0,0\n2,2.5,-1e-3,0,0.5,0,128,255\n");
    assert_eq!(
        centres(&s),
        vec![[0.0, 0.0, 0.0, 1.0], [2.5, -1e-3, 0.0, 0.5]]
    );
    assert_eq!(diffuse(&s, 0), DVec3::new(1.0, 0.0, 0.0));
    assert_eq!(diffuse(&s, 1), DVec3::new(0.0, 128.0 / 255.0, 1.0));
    // The framing: one Viewpoint, headlight off, two DirectionalLights.
    assert_eq!(s.viewpoints.len(), 1);
    assert!(!s.headlight);
    assert_eq!(s.lights.len(), 2);
}

#[test]
fn unit_colours_and_short_names() {
    // r beside g and b is red; the radius comes from --radius.
    let s = ir_with(
        "x,y,z,r,g,b\n1,2,3,0.25,0.5,1\n4,5,6,1,0,0\n",
        TableOptions {
            radius: Some(0.125),
            ..TableOptions::default()
        },
    );
    assert_eq!(
        centres(&s),
        vec![[1.0, 2.0, 3.0, 0.125], [4.0, 5.0, 6.0, 0.125]]
    );
    assert_eq!(diffuse(&s, 0), DVec3::new(0.25, 0.5, 1.0));
    assert_eq!(diffuse(&s, 1), DVec3::new(1.0, 0.0, 0.0));
    // Without g and b, r is the radius.
    let s = ir("x y z r\n1 2 3 0.5\n");
    assert_eq!(centres(&s), vec![[1.0, 2.0, 3.0, 0.5]]);
    // Colours of only 0 and 1 are 0-1, not 0-255.
    let s = ir_with(
        "x,y,z,red,green,blue\n0,0,0,1,0,1\n",
        TableOptions {
            radius: Some(1.0),
            ..TableOptions::default()
        },
    );
    assert_eq!(diffuse(&s, 0), DVec3::new(1.0, 0.0, 1.0));
    // ... unless told.
    let s = ir_with(
        "x,y,z,red,green,blue\n0,0,0,1,0,1\n",
        TableOptions {
            radius: Some(1.0),
            color_scale: Some(ColorScale::Byte),
            ..TableOptions::default()
        },
    );
    assert_eq!(diffuse(&s, 0), DVec3::new(1.0 / 255.0, 0.0, 1.0 / 255.0));
}

#[test]
fn semicolon_with_decimal_commas_and_units() {
    let s = ir("# exported\nPos X [nm];Pos Y [nm];Pos Z [nm];Diameter\n1,5;-2;3,25;1\n");
    assert_eq!(centres(&s), vec![[1.5, -2.0, 3.25, 0.5]]);
}

#[test]
fn byte_order_mark_and_crlf_line_ends() {
    // As spreadsheets write CSV.
    let s = ir("\u{feff}x,y,z,radius\r\n1,2,3,0.5\r\n4,5,6,1\r\n");
    assert_eq!(
        centres(&s),
        vec![[1.0, 2.0, 3.0, 0.5], [4.0, 5.0, 6.0, 1.0]]
    );
    let s = ir("\u{feff}1 2 3 0.5\r\n4 5 6 1\r\n");
    assert_eq!(
        centres(&s),
        vec![[1.0, 2.0, 3.0, 0.5], [4.0, 5.0, 6.0, 1.0]]
    );
    let s = ir("2\r\nwater\r\nO 0 0 0\r\nH 1 0 0\r\n");
    assert_eq!(
        centres(&s),
        vec![[0.0, 0.0, 0.0, 1.52], [1.0, 0.0, 0.0, 1.2]]
    );
}

#[test]
fn tab_separated_with_quoted_header() {
    let s = ir("\"x\"\t\"y\"\t\"z\"\t\"radius\"\n1\t2\t3\t4\n\n5\t6\t7\t8\n");
    assert_eq!(
        centres(&s),
        vec![[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]]
    );
}

#[test]
fn whitespace_headerless_with_comments_and_blank_lines() {
    let s = ir("# t x y z r\n  0 0 0 1\n\n1\t 1  1 0.5   \n# more\n2 2 2 0.25\n");
    assert_eq!(
        centres(&s),
        vec![
            [0.0, 0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0, 0.5],
            [2.0, 2.0, 2.0, 0.25]
        ]
    );
    // Three columns are x y z, with --radius.
    let s = ir_with(
        "1 2 3\n",
        TableOptions {
            radius: Some(2.0),
            ..TableOptions::default()
        },
    );
    assert_eq!(centres(&s), vec![[1.0, 2.0, 3.0, 2.0]]);
    // Forced white space on a file with single spaces.
    let s = ir_with(
        "x y z radius\n1 2 3 4\n",
        TableOptions {
            delimiter: Some(Delimiter::Whitespace),
            ..TableOptions::default()
        },
    );
    assert_eq!(centres(&s), vec![[1.0, 2.0, 3.0, 4.0]]);
}

#[test]
fn element_xyz_lines_with_columns() {
    // Headerless "element x y z" lines, named with --columns.
    let s = ir_with(
        "O 0 0 0\nH 0.757 0.586 0\nH -0.757 0.586 0\n",
        TableOptions {
            columns: columns(&["element,x,y,z"]),
            radius: Some(0.5),
            ..TableOptions::default()
        },
    );
    assert_eq!(s.spheres.len(), 3, "no row may be taken for a header");
    assert_eq!(centres(&s)[2], [-0.757, 0.586, 0.0, 0.5]);
    // A real XYZ file: atom count, comment line (here empty), atoms; one frame is read.
    let s = ir_with(
        "3\n\nO 0 0 0\nH 0.757 0.586 0\nH -0.757 0.586 0\n3\nframe 2\nO 9 9 9\nH 9 9 9\nH 9 9 9\n",
        TableOptions {
            radius: Some(0.5),
            ..TableOptions::default()
        },
    );
    assert_eq!(s.spheres.len(), 3);
    assert_eq!(centres(&s)[1], [0.757, 0.586, 0.0, 0.5]);
    // Without --radius, radii and colours come from the element (O: 1.52 A, CPK red).
    let s = ir("2\nwater, half\nO 0 0 0\nh 0.757 0.586 0\n");
    assert_eq!(
        centres(&s),
        vec![[0.0, 0.0, 0.0, 1.52], [0.757, 0.586, 0.0, 1.2]]
    );
    assert_eq!(diffuse(&s, 0), DVec3::new(1.0, 13.0 / 255.0, 13.0 / 255.0));
    assert_eq!(diffuse(&s, 1), DVec3::ONE);
}

#[test]
fn columns_map_other_names_by_name_and_number() {
    let s = ir_with(
        "a,b,c,size,q\n1,2,3,0.5,9\n",
        TableOptions {
            columns: columns(&["x=a,y=2", "z=C", "radius=size"]),
            ..TableOptions::default()
        },
    );
    assert_eq!(centres(&s), vec![[1.0, 2.0, 3.0, 0.5]]);
    // A positional list replaces a header the file has.
    let s = ir_with(
        "c1 c2 c3 c4\n1 2 3 4\n",
        TableOptions {
            columns: columns(&["skip,z,y,x"]),
            radius: Some(1.0),
            ..TableOptions::default()
        },
    );
    assert_eq!(centres(&s), vec![[4.0, 3.0, 2.0, 1.0]]);
}

#[test]
fn density_opacity_transparency_and_emission() {
    // sigma = 0.3 on radius 2: transparency exp(-1.2); read back as sigma.
    let s = ir("x,y,z,radius,density,emission_r,emission_g,emission_b\n0,0,0,2,0.3,0.5,0.25,0\n");
    let m = s.material_of(&s.spheres[0]);
    assert!(m.is_gas());
    assert!(
        (m.sigma(2.0) - 0.3).abs() <= 1e-15 * 0.3,
        "sigma {}",
        m.sigma(2.0)
    );
    assert_eq!(m.emissive, DVec3::new(0.5, 0.25, 0.0));
    let s = ir("x,y,z,radius,opacity,emission\n0,0,0,1,0.75,0.5\n");
    let m = s.material_of(&s.spheres[0]);
    assert_eq!(m.transparency, 0.25);
    assert_eq!(m.emissive, DVec3::splat(0.5));
    // Empty optional cells keep their defaults: an opaque, non-glowing, default-coloured row.
    let s =
        ir("x,y,z,radius,red,green,blue,density,emission\n0,0,0,1,,,,,\n1,1,1,1,0.5,0.5,0.5,2,\n");
    let (m0, m1) = (s.material_of(&s.spheres[0]), s.material_of(&s.spheres[1]));
    assert!(!m0.is_gas() && m0.diffuse == DVec3::splat(0.8) && m0.emissive == DVec3::ZERO);
    assert!(m1.is_gas() && m1.diffuse == DVec3::splat(0.5));
    let s = ir("x,y,z,radius,transparency\n0,0,0,1,0\n");
    let m = s.material_of(&s.spheres[0]);
    assert!(!m.is_gas());
}

#[test]
fn numbers_are_written_as_read() {
    let (s, text) = convert_with(
        "x,y,z,radius\n0.1000000000000000055511151231257827,1e-300,-0,1.5e+3\n",
        TableOptions::default(),
        FRAMED,
    )
    .unwrap();
    assert!(text.contains("position 0.1000000000000000055511151231257827 1e-300 -0 radius 1.5e+3"));
    assert_eq!(centres(&s), vec![[0.1, 1e-300, 0.0, 1500.0]]);
}

#[test]
fn plain_output_reads_as_the_proto_output() {
    let table = "x,y,z,radius,red,green,blue,opacity\n0,1,2,0.5,10,20,30,0.5\n3,4,5,1,40,50,60,1\n";
    let (a, _) = convert_with(table, TableOptions::default(), FRAMED).unwrap();
    let (b, text) = convert_with(
        table,
        TableOptions::default(),
        WriteOptions {
            plain: true,
            ..FRAMED
        },
    )
    .unwrap();
    assert!(!text.contains("PROTO"));
    assert_eq!(centres(&a), centres(&b));
    for k in 0..2 {
        let (ma, mb) = (a.material_of(&a.spheres[k]), b.material_of(&b.spheres[k]));
        assert_eq!(ma, mb);
    }
    assert_eq!(a.viewpoints.len(), b.viewpoints.len());
}

#[test]
fn framing_viewpoint_sees_every_particle_and_can_be_left_out() {
    let table = "x,y,z,radius\n-10,0,0,1\n10,5,-3,2\n0,-8,20,0.5\n";
    let s = ir(table);
    let vp = &s.viewpoints[0];
    for sp in &s.spheres {
        // Looking down -z: every sphere lies within the half angle, whole.
        let d = sp.center - vp.position;
        let off_axis = (d.x * d.x + d.y * d.y).sqrt();
        let angle = off_axis.atan2(-d.z) + (sp.radius / d.length()).asin();
        assert!(d.z < 0.0 && angle <= 0.5 * vp.field_of_view, "{angle}");
    }
    let (s, _) = convert_with(
        table,
        TableOptions::default(),
        WriteOptions {
            plain: false,
            extras: Extras {
                viewpoint: false,
                lights: false,
            },
        },
    )
    .unwrap();
    assert!(s.viewpoints.is_empty() && s.lights.is_empty() && s.headlight);
}

/// `file:LINE:FIELD: message` of a table that must fail.
#[test]
fn bad_rows_are_positioned_errors() {
    let d = TableOptions::default;
    let cases: &[(&str, &str)] = &[
        (
            "x,y,z,radius\n1,2,3,1\n1,abc,3,1\n",
            "t.csv:3:2: column \"y\": \"abc\" is not a number",
        ),
        (
            "x,y,z,radius\n1,2,3\n",
            "t.csv:2:4: the row has 3 fields; column 4 (\"radius\") is missing",
        ),
        (
            "x,y,z,radius\n1,2,3,-1\n",
            "t.csv:2:4: column \"radius\": radius -1 is not positive",
        ),
        (
            "x,y,z,radius\n1,2,3,0\n",
            "t.csv:2:4: column \"radius\": radius 0 is not positive",
        ),
        (
            "x,y,z,radius\n1,NaN,3,1\n",
            "t.csv:2:2: column \"y\": NaN is not a finite number",
        ),
        (
            "x,y,z,radius\n1,2,inf,1\n",
            "t.csv:2:3: column \"z\": inf is not a finite number",
        ),
        (
            "x,y,z,radius\n1,2,1e999,1\n",
            "t.csv:2:3: column \"z\": 1e999 is not a finite number",
        ),
        (
            "x,y,z,radius,red,green,blue\n0,0,0,1,0.5,1.5,0\n",
            "t.csv:2:6: column \"green\": 1.5 is outside 0..1",
        ),
        (
            "x,y,z,radius,red,green,blue\n0,0,0,1,10,300,0\n",
            "t.csv:2:6: column \"green\": 300 is outside 0..255",
        ),
        (
            "x,y,z,radius,opacity\n0,0,0,1,2\n",
            "t.csv:2:5: column \"opacity\": 2 is outside 0..1",
        ),
        (
            "x,y,z,radius,density\n0,0,0,1,-1\n",
            "t.csv:2:5: column \"density\": density -1 is negative",
        ),
        ("x,y,z\n0,0,0\n", "t.csv:1:1: no radius column"),
        ("x,y,radius\n0,0,1\n", "t.csv:1:1: no column for z"),
        (
            "x,y,z,radius,red\n0,0,0,1,1\n",
            "t.csv:1:1: a colour needs all three",
        ),
        (
            "x,y,z,radius,density,opacity\n0,0,0,1,1,1\n",
            "t.csv:1:1: columns for density and opacity",
        ),
        (
            "x,y,z,px,radius\n0,0,0,0,1\n",
            "t.csv:1:1: columns 1 (\"x\") and 4 (\"px\") both mean x",
        ),
        ("", "t.csv:1:1: the table is empty"),
        (
            "x,y,z,radius\n1,,3,1\n",
            "t.csv:2:2: column \"y\": the value is missing",
        ),
        (
            "x,y,z,radius,red,green,blue\n1,2,3,1,0.5,,0.5\n",
            "t.csv:2:6: column \"green\": empty, but",
        ),
        ("x,y,z,radius\n", "t.csv:2:1: no particles in the table"),
        (
            "1 2 3 4 5 6\n",
            "t.csv:1:1: the first row is numbers, not a header, and 6 columns are too many",
        ),
        (
            "3\ncomment\nC 0 0 0\n",
            "t.csv:4:1: the XYZ header promised 2 more atom lines",
        ),
        (
            "1\n\nQq 0 0 0\n",
            "t.csv:3:1: column \"element\": no radius known for element \"Qq\"",
        ),
    ];
    for (table, want) in cases {
        let e = err(table, d());
        assert!(
            e.starts_with(want),
            "table {table:?}\n got: {e}\nwant: {want}"
        );
    }
    // Colours guessed 0-255 from the first 1000 rows, then a fraction.
    let mut table = String::from("x,y,z,radius,red,green,blue\n");
    for _ in 0..1000 {
        table.push_str("0,0,0,1,200,0,0\n");
    }
    table.push_str("0,0,0,1,0.5,0,0\n");
    let e = err(&table, d());
    assert!(
        e.starts_with("t.csv:1002:5: column \"red\": 0.5 is not an integer"),
        "{e}"
    );
    // A fraction among the first rows makes them all 0-1.
    let e = err(
        "x,y,z,radius,red,green,blue\n0,0,0,1,200,0,0\n0,0,0,1,0.5,0,0\n",
        d(),
    );
    assert!(
        e.starts_with("t.csv:2:5: column \"red\": 200 is outside 0..1"),
        "{e}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Random particles written as a table, converted and read back, give the table's values.
    #[test]
    fn table_to_vrml_to_ir(
        rows in prop::collection::vec(
            (-1e6f64..1e6, -1e6f64..1e6, -1e-3f64..1e-3, 1e-6f64..1e3, 0u8..=255, 0u8..=255, 0u8..=255, prop::option::of(0f64..1.0)),
            1..40),
        sep in prop::sample::select(vec![",", ";", "\t", " "]),
    ) {
        let mut t = ["x", "y", "z", "radius", "red", "green", "blue", "opacity"].join(sep);
        t.push('\n');
        for (x, y, z, r, cr, cg, cb, o) in &rows {
            // The opacity column is full: missing values become 1 (opaque).
            let line = [x.to_string(), y.to_string(), z.to_string(), r.to_string(),
                cr.to_string(), cg.to_string(), cb.to_string(), o.unwrap_or(1.0).to_string()];
            t.push_str(&line.join(sep));
            t.push('\n');
        }
        let opts = TableOptions { color_scale: Some(ColorScale::Byte), ..TableOptions::default() };
        let (s, _) = convert_with(&t, opts, FRAMED).map_err(TestCaseError::fail)?;
        prop_assert_eq!(s.spheres.len(), rows.len());
        for (k, (x, y, z, r, cr, cg, cb, o)) in rows.iter().enumerate() {
            let sp = &s.spheres[k];
            prop_assert_eq!([sp.center.x, sp.center.y, sp.center.z, sp.radius], [*x, *y, *z, *r]);
            let m = s.material_of(sp);
            prop_assert_eq!(m.diffuse, DVec3::new(f64::from(*cr), f64::from(*cg), f64::from(*cb)) / 255.0);
            prop_assert_eq!(m.transparency, 1.0 - o.unwrap_or(1.0));
        }
    }
}

/// Found by fuzzing: particles near the largest f64 made the framing Viewpoint infinite, which
/// the reader rightly refuses. It is computed without overflow where it fits, and left out
/// (with a note) where it cannot.
#[test]
fn framing_huge_coordinates() {
    let (s, _) = convert_with(
        "x,y,z,radius\n-1e300,0,0,1e299\n1e300,2e300,-1e300,1\n",
        TableOptions::default(),
        FRAMED,
    )
    .unwrap();
    assert!(s.viewpoints[0].position.is_finite());
    let input: Box<dyn std::io::Read> = Box::new(std::io::Cursor::new(
        b"x,y,z,radius\n-1.7e308,0,0,1\n1.7e308,0,0,1\n".to_vec(),
    ));
    let (out, summary) = convert("t.csv", input, Vec::new(), TableOptions::default(), FRAMED)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(summary
        .notes
        .iter()
        .any(|n| n.contains("no Viewpoint written")));
    let (s, _) = load_str(
        "out.wrl",
        &String::from_utf8(out).unwrap(),
        &LoadOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(s.viewpoints.is_empty() && s.spheres.len() == 2);
}

#[test]
fn profile_and_width_columns_become_gas_particles() {
    use gtsphere::scene::Profile;
    let table = "x,y,z,radius,density,profile,width\n\
                 0,0,0,1,0.5,linear,0.3\n\
                 1,0,0,0.5,2,gaussian,0.25\n\
                 2,0,0,0.5,2,,0.25\n\
                 3,0,0,0.5,3,quadratic,\n\
                 4,0,0,0.5,1,gaussian,\n";
    let (s, text) = convert_with(table, TableOptions::default(), FRAMED).unwrap();
    assert!(text.contains("PROTO GasParticle ["), "{text}");
    let m = |k: usize| s.material_of(&s.spheres[k]);
    let got: Vec<Profile> = (0..5).map(|k| m(k).profile).collect();
    assert_eq!(
        got,
        [
            // A width for another profile is ignored (a width column fills every row).
            Profile::Linear,
            Profile::Gaussian { width: 0.25 },
            // An empty cell: constant.
            Profile::Constant,
            Profile::Quadratic,
            Profile::Gaussian { width: 1.0 / 3.0 },
        ]
    );
    // A density is sigma0, the value at the centre: the diameter's optical depth is
    // 2 r I_f sigma0, I_f = 1/2 for linear, 2/3 for quadratic and 1 for constant.
    let sigma0 = |k: usize, i_f: f64| -m(k).transparency.ln() / (2.0 * s.spheres[k].radius * i_f);
    assert!((sigma0(0, 0.5) - 0.5).abs() < 1e-15, "{}", sigma0(0, 0.5));
    assert!((sigma0(2, 1.0) - 2.0).abs() < 1e-15);
    let i_gauss = Profile::Gaussian { width: 0.25 }.integral();
    assert!((sigma0(1, i_gauss) - 2.0).abs() < 1e-14);
    assert!((sigma0(3, 2.0 / 3.0) - 3.0).abs() < 1e-14);
}

#[test]
fn bad_profiles_are_positioned_errors() {
    let e = err(
        "x,y,z,radius,profile\n0,0,0,1,linear\n1,0,0,1,fuzzy\n",
        TableOptions::default(),
    );
    assert!(
        e.contains("t.csv:3:5: column \"profile\": unknown density profile `fuzzy`"),
        "{e}"
    );
    let e = err(
        "x,y,z,radius,profile,width\n0,0,0,1,gaussian,1.5\n",
        TableOptions::default(),
    );
    assert!(
        e.contains("t.csv:2:6: column \"width\": gaussian width 1.5 is outside (0, 1]"),
        "{e}"
    );
    let plain = WriteOptions {
        plain: true,
        ..FRAMED
    };
    let e = convert_with(
        "x,y,z,radius,profile\n0,0,0,1,linear\n",
        TableOptions::default(),
        plain,
    )
    .expect_err("refused");
    assert!(e.contains("the profile column needs the PROTO form"), "{e}");
}

#[test]
fn a_header_of_thousands_of_columns_is_refused_and_messages_stay_short() {
    let names: Vec<String> = (0..5000).map(|i| format!("c{i}")).collect();
    let table = format!("{}\n{}\n", names.join(","), vec!["1"; 5000].join(","));
    let e = err(&table, TableOptions::default());
    assert_eq!(
        e,
        "t.csv:1:1: the first row has 5000 columns: a particle table has at most 4096"
    );
    // Within the bound, a message lists 16 columns and counts the rest.
    let names: Vec<String> = ["x", "y", "z"]
        .map(String::from)
        .into_iter()
        .chain((0..40).map(|i| format!("c{i}")))
        .collect();
    let table = format!("{}\n{}\n", names.join(","), vec!["1"; 43].join(","));
    let e = err(&table, TableOptions::default());
    assert!(e.contains("(columns: x, y, z, c0, c1, c2, c3, c4, c5, c6, c7, c8, c9, c10, c11, c12, and 27 more)"), "{e}");
    assert!(e.len() < 300, "{e}");
}

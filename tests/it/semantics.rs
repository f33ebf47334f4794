//! What the IR means: transforms, ellipsoids, light scoping, Switch, LOD, materials, bindables,
//! DEF/USE, PROTO expansion, and what is read but not modelled (an EXTERNPROTO whose urls do
//! not load, Script, ROUTE).
//! Expected values are worked out by hand in each test.

use glam::DVec3;
use gtsphere::scene::Light;

use super::support::{close, scene};

const BALL: &str = "Shape { geometry Sphere {} }";

#[test]
fn translation_after_children_applies() {
    let (s, _) = scene(&format!(
        "Transform {{ children {BALL} translation 1 2 3 }}"
    ));
    assert_eq!(s.spheres[0].center.to_array(), [1.0, 2.0, 3.0]);
}

#[test]
fn rotation_then_translation() {
    // Sphere at local (1,0,0); rotate 90 degrees about z -> (0,1,0); then translate (0,0,5).
    let (s, _) = scene(&format!(
        "Transform {{ translation 0 0 5 rotation 0 0 1 1.5707963267948966 children Transform {{ translation 1 0 0 children {BALL} }} }}"
    ));
    let c = s.spheres[0].center;
    assert!(
        close(c.x, 0.0, 1e-15) && close(c.y, 1.0, 1e-15) && close(c.z, 5.0, 1e-15),
        "{c}"
    );
}

#[test]
fn uniform_scale_scales_the_radius_about_the_center_field() {
    // T * C * S * -C: point p=(0,0,0) -> C + S(p - C) = (1,1,1) + 2*(-1,-1,-1) = (-1,-1,-1).
    let (s, _) = scene(
        "Transform { scale 2 2 2 center 1 1 1 children Shape { geometry Sphere { radius 0.5 } } }",
    );
    let b = s.spheres[0];
    assert_eq!(b.center.to_array(), [-1.0, -1.0, -1.0]);
    assert_eq!(b.radius, 1.0);
    assert_eq!(b.ellipsoid, None);
}

#[test]
fn non_uniform_scale_makes_an_ellipsoid() {
    let (s, _) = scene(
        "Transform { translation 1 0 0 scale 1 2 3 children Shape { geometry Sphere { radius 2 } } }",
    );
    let b = s.spheres[0];
    assert_ne!(b.ellipsoid, None);
    let e = s.ellipsoids[b.ellipsoid.expect("an ellipsoid").index()];
    // The unit sphere maps to semi-axes 2, 4, 6 centred at (1,0,0).
    assert_eq!(e.transform_point3(DVec3::X).to_array(), [3.0, 0.0, 0.0]);
    assert_eq!(e.transform_point3(DVec3::Y).to_array(), [1.0, 4.0, 0.0]);
    assert_eq!(e.transform_point3(DVec3::Z).to_array(), [1.0, 0.0, 6.0]);
    let bb = s.bounds().expect("bounds");
    assert_eq!((bb.min, bb.max), ([-1.0, -4.0, -6.0], [3.0, 4.0, 6.0]));
    assert_eq!(s.ellipsoid_count(), 1);
}

#[test]
fn scale_orientation_rotates_the_scale_axes() {
    // Scale 2 along the axis that scaleOrientation (90 degrees about z) turns x into: world y.
    let (s, _) = scene(&format!(
        "Transform {{ scale 2 1 1 scaleOrientation 0 0 1 1.5707963267948966 children {BALL} }}"
    ));
    let e = s.ellipsoids[s.spheres[0].ellipsoid.expect("an ellipsoid").index()];
    let y = e.transform_point3(DVec3::Y);
    let x = e.transform_point3(DVec3::X);
    assert!(close(y.y, 2.0, 1e-15) && close(x.x, 1.0, 1e-15), "{x} {y}");
}

#[test]
fn rotation_about_a_zero_axis_is_no_rotation() {
    let (s, _) = scene(&format!(
        "Transform {{ rotation 0 0 0 0 translation 1 0 0 children {BALL} }}"
    ));
    assert_eq!(s.spheres[0].center.to_array(), [1.0, 0.0, 0.0]);
}

#[test]
fn zero_scale_hides_contents_with_a_warning() {
    let (s, r) = scene(&format!(
        "Transform {{ scale 0 1 1 children {BALL} }}\n{BALL}"
    ));
    assert_eq!(s.spheres.len(), 1);
    assert!(r.warnings[0].message.contains("zero or non-finite scale"));
}

#[test]
fn directional_light_lights_only_its_siblings() {
    let (s, _) = scene(&format!(
        "{BALL}\nGroup {{ children [ {BALL} DirectionalLight {{ direction 0 -1 0 }} Transform {{ children {BALL} }} ] }}\n{BALL}\nDirectionalLight {{}}"
    ));
    let scopes: Vec<(u32, u32)> = s
        .lights
        .iter()
        .map(|l| match l {
            Light::Directional(d) => d.scope.range(s.spheres.len()),
            Light::Point(_) => panic!("no point lights here"),
        })
        .collect();
    assert_eq!(scopes, vec![(1, 3), (0, 4)]);
}

#[test]
fn light_fields_and_transforms() {
    let (s, _) = scene(
        "Transform { translation 0 0 1 scale 2 2 2 children [\n\
           PointLight { location 1 0 0 radius 10 intensity 0.5 attenuation 1 0.5 0 on FALSE }\n\
           DirectionalLight { direction 0 0 2 color 1 0 0 ambientIntensity 0.25 } ] }",
    );
    match s.lights[0] {
        Light::Point(p) => {
            assert_eq!(p.location.to_array(), [2.0, 0.0, 1.0]);
            assert_eq!((p.radius, p.intensity, p.on), (20.0, 0.5, false));
            assert_eq!(p.attenuation.to_array(), [1.0, 0.5, 0.0]);
        }
        _ => panic!("first light is the PointLight"),
    }
    match s.lights[1] {
        Light::Directional(d) => {
            assert_eq!(d.direction.to_array(), [0.0, 0.0, 1.0]);
            assert_eq!(
                (d.color.to_array(), d.ambient_intensity),
                ([1.0, 0.0, 0.0], 0.25)
            );
        }
        _ => panic!("second light is the DirectionalLight"),
    }
}

#[test]
fn switch_shows_only_which_choice() {
    let (s, _) = scene(&format!(
        "Switch {{ choice [ Shape {{ geometry Sphere {{ radius 1 }} }} Shape {{ geometry Sphere {{ radius 2 }} }} ] whichChoice 1 }}\n\
         Switch {{ choice [ {BALL} ] }}"
    ));
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(s.spheres[0].radius, 2.0);
}

#[test]
fn defs_inside_unchosen_switch_children_are_usable() {
    let (s, _) =
        scene("Switch { choice DEF B Shape { geometry Sphere { radius 3 } } }\nUSE B\nUSE B");
    assert_eq!(s.spheres.len(), 2);
    assert_eq!(s.spheres[0].radius, 3.0);
}

#[test]
fn lod_renders_its_first_level_only() {
    let (s, _) = scene(
        "LOD { range [ 10 ] level [ Shape { geometry Sphere { radius 1 } } Shape { geometry Sphere { radius 2 } } ] }",
    );
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(s.spheres[0].radius, 1.0);
}

#[test]
fn collision_proxy_is_not_rendered() {
    let (s, _) = scene(&format!(
        "Collision {{ proxy {BALL} children [ {BALL} {BALL} ] }}"
    ));
    assert_eq!(s.spheres.len(), 2);
}

#[test]
fn materials_are_shared_not_copied() {
    let m = "appearance Appearance { material Material { diffuseColor 0.1 0.2 0.3 } }";
    let (s, _) = scene(&format!(
        "Shape {{ {m} geometry Sphere {{}} }}\nShape {{ {m} geometry Sphere {{}} }}\n\
         DEF A Appearance {{ material Material {{ transparency 0.5 }} }}\n\
         Shape {{ appearance USE A geometry Sphere {{}} }}\nShape {{ appearance USE A geometry Sphere {{}} }}\n{BALL}"
    ));
    let ids: Vec<u32> = s.spheres.iter().map(|b| b.material).collect();
    assert_eq!(ids[0], ids[1]);
    assert_eq!(ids[2], ids[3]);
    assert_ne!(ids[0], ids[2]);
    // Records: unlit white (index 0), the lit opaque one, the gas one; the colours are the
    // spheres' own.
    assert_eq!(s.materials.len(), 3);
    assert!(s.material_of(&s.spheres[4]).unlit);
    assert_eq!(s.material_of(&s.spheres[4]).diffuse, DVec3::ONE);
    assert_eq!(
        s.material_of(&s.spheres[1]).diffuse.to_array(),
        [0.1, 0.2, 0.3]
    );
    assert_eq!(s.gas_count(), 2);
    let gas = s.material_of(&s.spheres[2]);
    assert!(close(gas.sigma(1.0), 0.5f64.ln().abs() / 2.0, 1e-15));
}

#[test]
fn many_colours_in_scrambled_order_share_one_record() {
    // 20 000 colours over 100 000 spheres in a scrambled order, Shapes nested in Transforms
    // and a Group: the materials differ in their colour alone, so they share one record, and
    // every sphere keeps its own colour, packed (none is listed).
    let colour = |k: usize| {
        let c = (k * 7919 + k / 3) % 20_000;
        [(c % 100) as f64 / 100.0, (c / 100) as f64 / 200.0, 0.5]
    };
    let mut text = String::from("Group { children [\n");
    for k in 0..100_000 {
        let [r, g, b] = colour(k);
        text += &format!(
            "Transform {{ translation {k} 0 0 children Shape {{ appearance Appearance {{ \
             material Material {{ diffuseColor {r} {g} {b} }} }} geometry Sphere {{}} }} }}\n"
        );
    }
    text += "] }\n";
    let (s, _) = scene(&text);
    assert_eq!(s.spheres.len(), 100_000);
    // The unlit white of a Shape without a Material comes first, then the lit one.
    assert_eq!(s.materials.len(), 2);
    assert!(s.materials.record(0).unlit);
    assert!(!s.materials.record(1).unlit);
    assert!(s.materials.listed_colors().is_empty());
    for (k, b) in s.spheres.iter().enumerate() {
        assert_eq!(b.center.x, k as f64);
        assert_eq!(s.material_of(b).diffuse.to_array(), colour(k));
    }
}

#[test]
fn vrml_material_defaults() {
    let (s, _) =
        scene("Shape { appearance Appearance { material Material {} } geometry Sphere {} }");
    let m = s.material_of(&s.spheres[0]);
    assert_eq!(m.diffuse.to_array(), [0.8; 3]);
    assert_eq!(
        (m.ambient_intensity, m.shininess, m.transparency),
        (0.2, 0.2, 0.0)
    );
    assert_eq!((m.emissive, m.specular), (DVec3::ZERO, DVec3::ZERO));
    assert!(!m.unlit);
}

#[test]
fn first_navigation_info_and_background_are_bound() {
    let (s, _) = scene(
        "NavigationInfo { headlight FALSE }\nNavigationInfo { headlight TRUE }\n\
         Background { skyColor [ 0.1 0.2 0.3, 1 1 1 ] }\nBackground { skyColor 1 0 0 }",
    );
    assert!(!s.headlight);
    assert_eq!(s.background.to_array(), [0.1, 0.2, 0.3]);
    let (s, _) = scene(BALL);
    assert!(s.headlight);
    assert_eq!(s.background, DVec3::ZERO);
}

#[test]
fn viewpoints_are_transformed_and_named() {
    let (s, _) = scene(
        "Transform { translation 0 0 -5 rotation 0 1 0 3.141592653589793 children\n\
         DEF Front Viewpoint { position 0 0 10 fieldOfView 0.5 description \"front\" } }",
    );
    let v = &s.viewpoints[0];
    assert_eq!(v.name.as_deref(), Some("Front"));
    assert_eq!(v.description, "front");
    assert_eq!(v.field_of_view, 0.5);
    assert!(
        close(v.position.z, -15.0, 1e-12) && v.position.x.abs() < 1e-12,
        "{}",
        v.position
    );
    // Looking down -z, turned by pi about y: now looking down +z.
    let look = v.orientation * DVec3::NEG_Z;
    assert!(close(look.z, 1.0, 1e-12), "{look}");
}

#[test]
fn inline_of_a_local_file_and_refusal_of_urls() {
    let dir = std::env::temp_dir().join(format!("gtsphere-inline-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("sub")).expect("tmp");
    std::fs::write(
        dir.join("main.wrl"),
        "#VRML V2.0 utf8\nTransform { translation 10 0 0 children Inline { url [ \"http://example.org/x.wrl\" \"sub/part.wrl\" ] } }\nInline { url \"missing.wrl\" }\nInline { url \"/etc/passwd\" }\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("sub/part.wrl"),
        "#VRML V2.0 utf8\nDEF B Shape { geometry Sphere {} }\nTransform { translation 1 0 0 children USE B }\nDirectionalLight {}\n",
    )
    .expect("write");
    let (s, r) =
        gtsphere::vrml::load_path(&dir.join("main.wrl"), &Default::default()).expect("inline");
    let xs: Vec<f64> = s.spheres.iter().map(|b| b.center.x).collect();
    assert_eq!(xs, vec![10.0, 11.0]);
    match s.lights[0] {
        Light::Directional(d) => assert_eq!(d.scope.range(s.spheres.len()), (0, 2)),
        _ => panic!("directional"),
    }
    let msgs: Vec<&str> = r.warnings.iter().map(|w| w.message.as_str()).collect();
    assert_eq!(msgs.len(), 2, "{msgs:?}");
    assert!(msgs[0].contains("'missing.wrl' (no such file)"));
    assert!(msgs[1].contains("'/etc/passwd' (not a local relative path)"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A DEF'd Group holding an Inline, USE'd once more: the file is drawn twice, once per
/// instance (it was drawn three times: the USE replayed the file's events and read it again).
#[test]
fn a_used_inline_draws_its_file_once_per_instance() {
    let dir = std::env::temp_dir().join(format!("gtsphere-inline-use-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    std::fs::write(
        dir.join("b.wrl"),
        "#VRML V2.0 utf8\nDEF S Shape { geometry Sphere { } }\nTransform { translation 0 1 0 children USE S }\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("a.wrl"),
        "#VRML V2.0 utf8\nDEF G Group { children Inline { url \"b.wrl\" } }\nTransform { translation 3 0 0 children USE G }\n",
    )
    .expect("write");
    let (s, _) = gtsphere::vrml::load_path(&dir.join("a.wrl"), &Default::default()).expect("load");
    let mut at: Vec<(f64, f64)> = s.spheres.iter().map(|b| (b.center.x, b.center.y)).collect();
    at.sort_by(|p, q| p.partial_cmp(q).unwrap());
    assert_eq!(at, vec![(0.0, 0.0), (0.0, 1.0), (3.0, 0.0), (3.0, 1.0)]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn inline_cycles_are_refused() {
    let dir = std::env::temp_dir().join(format!("gtsphere-cycle-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    std::fs::write(
        dir.join("a.wrl"),
        "#VRML V2.0 utf8\nInline { url \"b.wrl\" }\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("b.wrl"),
        "#VRML V2.0 utf8\nInline { url \"a.wrl\" }\n",
    )
    .expect("write");
    let e = gtsphere::vrml::load_path(&dir.join("a.wrl"), &Default::default()).expect_err("cycle");
    assert!(e.to_string().contains("includes itself (a cycle)"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file whose `levels` nested DEFs each USE the one before twice: 2^(levels - 1) spheres.
fn use_bomb(levels: usize) -> String {
    let mut text = String::from("#VRML V2.0 utf8\nDEF L0 Shape { geometry Sphere {} }\n");
    for i in 1..levels {
        text.push_str(&format!(
            "DEF L{i} Group {{ children [ USE L{} USE L{} ] }}\n",
            i - 1,
            i - 1
        ));
    }
    text
}

#[test]
fn exponential_use_blowup_is_refused() {
    let opts = gtsphere::vrml::LoadOptions {
        expansion_base: 1_000_000,
        ..Default::default()
    };
    let text = use_bomb(40);
    let e = gtsphere::vrml::load_bytes("bomb.wrl", text.clone().into_bytes(), &opts)
        .expect_err("blow-up");
    let limit = 1_000_000 + 16 * text.len();
    assert!(
        e.to_string().contains(&format!(
            "this USE takes the scene past its expansion limit: {limit} nodes and values \
             (1000000 plus 16 per byte of text read)"
        )),
        "{e}"
    );
}

/// The expansion limit grows with the text read: many PROTO instances, each a few nodes, load
/// past the base (a hundred million particles as `convert` writes them are 5e8 nodes), while
/// a blow-up of the same size is still refused.
#[test]
fn many_proto_instances_load_past_the_base_but_a_blowup_does_not() {
    let mut text = String::from(
        "#VRML V2.0 utf8\nPROTO P [ field SFVec3f at 0 0 0 ] { Transform { translation IS at \
         children Shape { appearance Appearance { material Material { } } geometry Sphere { } } } }\n",
    );
    for i in 0..2000 {
        text.push_str(&format!("P {{ at {i} 0 0 }}\n"));
    }
    for replay_every_instance in [false, true] {
        let opts = gtsphere::vrml::LoadOptions {
            expansion_base: 1000,
            replay_every_instance,
            ..Default::default()
        };
        let (scene, report) =
            gtsphere::vrml::load_bytes("many.wrl", text.clone().into_bytes(), &opts)
                .expect("loads");
        assert_eq!(scene.spheres.len(), 2000);
        assert!(report.expansion > 1000, "{}", report.expansion);
        // The same instances reached through USE nest: far more nodes than bytes.
        let bomb = use_bomb(20);
        assert!(bomb.len() < text.len());
        let e =
            gtsphere::vrml::load_bytes("bomb.wrl", bomb.into_bytes(), &opts).expect_err("blow-up");
        assert!(
            e.to_string().contains("plus 16 per byte of text read"),
            "{e}"
        );
    }
}

/// A PROTO may take a standard node type's name: from its declaration on, that name means
/// the PROTO (the reader skips the PROTO lookup for standard names only until one is declared).
#[test]
fn a_proto_named_like_a_standard_node_shadows_it_after_its_declaration() {
    let (s, _) = scene(
        "Group { children Shape { geometry Sphere { } } }\n\
         PROTO Group [ field SFVec3f at 0 0 0 ] {\n\
           Transform { translation IS at children Shape { geometry Sphere { radius 2 } } }\n\
         }\n\
         Group { at 5 0 0 }",
    );
    assert_eq!(s.spheres.len(), 2);
    assert_eq!(s.spheres[0].center.to_array(), [0.0, 0.0, 0.0]);
    assert_eq!(s.spheres[0].radius, 1.0);
    assert_eq!(s.spheres[1].center.to_array(), [5.0, 0.0, 0.0]);
    assert_eq!(s.spheres[1].radius, 2.0);
}

/// One instance after another reuses the recorded names and value tables: each instance
/// still gets its own values, and a field it leaves out its own default.
#[test]
fn consecutive_proto_instances_keep_their_own_values() {
    let (s, _) = scene(
        "PROTO P [ field SFVec3f p 0 0 0 field SFFloat r 1 ] {\n\
           Transform { translation IS p children Shape { geometry Sphere { radius IS r } } }\n\
         }\n\
         P { p 1 0 0 r 0.5 }\n\
         P { r 0.25 }\n\
         P { p 0 0 3 }",
    );
    let got: Vec<([f64; 3], f64)> = s
        .spheres
        .iter()
        .map(|x| (x.center.to_array(), x.radius))
        .collect();
    assert_eq!(
        got,
        vec![
            ([1.0, 0.0, 0.0], 0.5),
            ([0.0, 0.0, 0.0], 0.25),
            ([0.0, 0.0, 3.0], 1.0)
        ]
    );
}

#[test]
fn the_same_def_name_defined_again_later_one_wins() {
    let (s, _) = scene(
        "DEF M Material { diffuseColor 1 0 0 }\n\
         Shape { appearance Appearance { material USE M } geometry Sphere {} }\n\
         DEF M Material { diffuseColor 0 0 1 }\n\
         Shape { appearance Appearance { material USE M } geometry Sphere {} }",
    );
    let m0 = s.material_of(&s.spheres[0]);
    let m1 = s.material_of(&s.spheres[1]);
    assert_eq!(m0.diffuse.to_array(), [1.0, 0.0, 0.0]);
    assert_eq!(m1.diffuse.to_array(), [0.0, 0.0, 1.0]);
}

#[test]
fn use_inside_a_def_keeps_the_meaning_it_had_when_read() {
    let (s, _) = scene(
        "DEF M Material { diffuseColor 1 0 0 }\n\
         DEF S Shape { appearance Appearance { material USE M } geometry Sphere {} }\n\
         DEF M Material { diffuseColor 0 0 1 }\n\
         USE S",
    );
    assert_eq!(s.spheres.len(), 2);
    for b in &s.spheres {
        assert_eq!(s.material_of(b).diffuse.x, 1.0);
    }
}

#[test]
fn proto_with_is_is_expanded() {
    let (s, _) = scene(
        "PROTO Ball [ field SFColor c 1 1 1 field SFFloat r 1 exposedField SFVec3f at 0 0 0 ] {\n\
           Transform { translation IS at children Shape {\n\
             appearance Appearance { material Material { diffuseColor IS c } }\n\
             geometry Sphere { radius IS r } } }\n\
         }\n\
         Ball { c 1 0 0 r 0.5 at 1 2 3 }\n\
         Ball { }",
    );
    assert_eq!(s.spheres.len(), 2);
    let (a, b) = (s.spheres[0], s.spheres[1]);
    assert_eq!((a.center.to_array(), a.radius), ([1.0, 2.0, 3.0], 0.5));
    assert_eq!((b.center.to_array(), b.radius), ([0.0, 0.0, 0.0], 1.0));
    assert_eq!(s.material_of(&a).diffuse.to_array(), [1.0, 0.0, 0.0]);
    assert_eq!(s.material_of(&b).diffuse.to_array(), [1.0, 1.0, 1.0]);
}

#[test]
fn node_valued_proto_fields_and_nested_protos() {
    let (s, _) = scene(
        "PROTO Red [] { Material { diffuseColor 1 0 0 } }\n\
         PROTO Holder [ field MFNode kids [] ] { Group { children IS kids } }\n\
         Holder { kids [ Shape { appearance Appearance { material Red {} } geometry Sphere {} }\n\
                         Shape { geometry Sphere { radius 3 } } ] }",
    );
    assert_eq!(s.spheres.len(), 2);
    assert_eq!(
        s.material_of(&s.spheres[0]).diffuse.to_array(),
        [1.0, 0.0, 0.0]
    );
    assert!(s.material_of(&s.spheres[1]).unlit);
}

#[test]
fn only_the_first_node_of_a_proto_body_is_rendered() {
    let (s, _) = scene(&format!("PROTO Two [] {{ {BALL} {BALL} }}\nTwo {{}}"));
    assert_eq!(s.spheres.len(), 1);
}

#[test]
fn externproto_instances_are_skipped_with_a_warning() {
    let (s, r) = scene(&format!(
        "EXTERNPROTO Fancy [ field SFFloat x ] [ \"urn:fancy\" \"fancy.wrl#Fancy\" ]\nFancy {{ x 1 }}\n{BALL}"
    ));
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(r.skipped.get("Fancy"), Some(&1));
    assert!(r
        .warnings
        .iter()
        .any(|w| w.message.contains("EXTERNPROTO Fancy")));
}

#[test]
fn route_and_script_are_read_and_ignored() {
    let (s, r) = scene(&format!(
        "DEF T TimeSensor {{ loop TRUE }}\n\
         DEF S Script {{ eventIn SFTime tick field SFNode me USE T url \"javascript: function tick(v) {{ }}\" }}\n\
         DEF X Transform {{ children {BALL} }}\n\
         ROUTE T.time TO S.tick\n"
    ));
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(r.skipped.get("Script"), Some(&1));
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn deeply_nested_transforms_compose() {
    let n = 1000;
    let mut text = String::from("#VRML V2.0 utf8\n");
    for _ in 0..n {
        text.push_str("Transform { translation 0.001 0 0 children\n");
    }
    text.push_str("Shape { geometry Sphere {} }");
    for _ in 0..n {
        text.push_str("}\n");
    }
    let (s, _) = super::support::load(&text);
    assert!(
        close(s.spheres[0].center.x, 1.0, 1e-12),
        "{}",
        s.spheres[0].center.x
    );
}

//! Hand-counted expectations for the conformance suites' files (the counting rules are the
//! parent's).

use super::Expected;

pub const CONFORMANCE: &[Expected] = &[
    // ------------------------------------------------------------------ conformance
    // PROTO with SFNode IS fields: 6 instances (MaterialSphere x2, MaterialSphereDefaultRed x2,
    // MaterialSphereDefaultYellow x2), each expands to Shape{Sphere} -> 6 spheres (the
    // `MaterialSphere { }` one has material NULL -> opaque; the DefaultYellow default
    // Appearance does `material USE YellowMat`, DEF'd earlier in an instance). No
    // transparency anywhere. Each of the 6 Transforms also has a label Shape{Text} -> Text 6.
    Expected {
        path: "conformance/castle-demo-models/prototypes/proto_nodes.wrl",
        spheres: 6,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[("Text", 6)],
    },
    // `MySphere { }` (1) + plain Shape radius 4 (1) + `MySphere { whatever 456.0 }` (1;
    // MySphere is re-declared with a field before this use — either declaration gives one
    // Sphere) + Shape radius 2 with `DEF AWithMaterial Appearance{material RedMaterial{}}` (1)
    // + Shape with `appearance USE AWithMaterial` (1) + Shape with RedMaterial (1) = 6.
    // RedMaterial is a PROTO declared inside a Transform body expanding to a Material
    // (modelled, not counted, no transparency).
    Expected {
        path: "conformance/castle-demo-models/prototypes/proto_ultra_simple.wrl",
        spheres: 6,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // Top level: DEF MySphere Shape{Sphere} (1) + USE MySphere (1); SomeSpheres{} expands to
    // its first body node only: Group{ DEF MySphere (1) + Transform{USE MySphere} (1) } (the
    // trailing Box Shape / USE / Material in the PROTO body are not part of the scene, so
    // boxes 0 although `grep -c Box` = 1); then
    // `USE MySphere` at top level (outer, blue one) (1) -> 5. ProtoEventsIsTest never
    // instanced.
    Expected {
        path: "conformance/castle-demo-models/prototypes/proto_other.wrl",
        spheres: 5,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // `T813blatnikZ { }` -> first body node `MatLib { matrose Material{...} }` -> nested
    // PROTO -> Shape{appearance Appearance{material IS matrose} geometry Sphere} = 1 sphere;
    // plus one Transform{Shape{Text}} -> Text 1.
    Expected {
        path: "conformance/castle-demo-models/prototypes/proto_nested_expand.wrl",
        spheres: 1,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[("Text", 1)],
    },
    // The Switch has no whichChoice (default -1) -> none of its 4 choices drawn. The three
    // top-level Transforms each `USE SphereColumn` (Group of 3 Transforms each USE-ing a
    // Red/Green/Blue sphere Shape) -> 3 x 3 = 9 spheres.
    Expected {
        path: "conformance/castle-demo-models/vrml_engine_doc_simple_examples/reuse_switch.wrl",
        spheres: 9,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // Group children: Viewpoint (1); Transform{DEF SNormal sphere} (1); DEF STransp sphere
    // with transparency 0.5 (1, gas); DirectionalLight (1); DEF LowerTransform{ USE SNormal
    // (1), USE STransp (1, gas), DirectionalLight (1), DEF SSmall sphere (1), USE SNormal (1) };
    // USE SSmall (1); Transform{USE SNormal} (1). Spheres 8 of which gas 2; DirectionalLight 2.
    Expected {
        path: "conformance/castle-demo-models/lights_materials/directional_light_scope.wrl",
        spheres: 8,
        gas: 2,
        point_lights: 0,
        directional_lights: 2,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // 3 top-level Viewpoints; Group with 3 Transforms each holding `Icon {}` -> PROTO body
    // DEF Location Transform{Shape{Sphere}} -> 3 spheres. (ImageTexture is commented out.)
    Expected {
        path: "conformance/openvrml/models/SimplePROTO.wrl",
        spheres: 3,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 3,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // Group: 3 Transforms each with an Anchor (children walked): Box (DEF A1 Appearance),
    // Sphere (appearance USE A1), Cone (USE A1); then DEF DefaultView Viewpoint and
    // DEF NiceView Viewpoint -> Viewpoints 2. Box 1 and Cone 1 (`grep -c` 1 each, no USE of
    // a geometry) are now surfaces; nothing skipped.
    Expected {
        path: "conformance/openvrml/models/Anchor.wrl",
        spheres: 1,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 2,
        boxes: 1,
        cylinders: 0,
        cones: 1,
        triangles: 0,
        skipped: &[],
    },
    // Spheres: DEF Ball (1) + USE Ball in Middle (1) + USE Ball in head (1) + DEF Eye (1) +
    // USE Eye (1) = 5 (the `# transparency .2` is a comment -> opaque). Surfaces: Cone 1
    // (nose), Cylinder 2 (hat, second via appearance USE Felt; `grep -c Cylinder` = 2, no
    // geometry USE). Triangles: the 2 Extrusions (the arm, DEF Tipper; read from lines 163 and
    // 183) each have a closed 9-point crossSection (8 distinct points, an octagon) and 3 spine
    // points: 2 x 8 side quads = 32 triangles, plus the two default caps, octagons of 6
    // triangles each: 44 each, 88 in all. Skipped: VisibilitySensor 1 (DEF See, a Transform
    // child), TimeSensor 1, CoordinateInterpolator 1, PositionInterpolator 1, WorldInfo 2
    // (first and last node).
    // Background/NavigationInfo modelled; Viewpoint 1; 5 ROUTEs ignored.
    Expected {
        path: "conformance/openvrml/models/snoman.wrl",
        spheres: 5,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 1,
        boxes: 0,
        cylinders: 2,
        cones: 1,
        triangles: 88,
        skipped: &[
            ("CoordinateInterpolator", 1),
            ("PositionInterpolator", 1),
            ("TimeSensor", 1),
            ("VisibilitySensor", 1),
            ("WorldInfo", 2),
        ],
    },
    // gzip file (zcat to read). DEF RenderBefore Group = ILS (1) + Transform{DEF Krzyzyk
    // Group{ILS, PointSet}} + Transform{USE Krzyzyk (ILS, PointSet), Shape{Text}} -> per
    // instance ILS 3, PointSet 2, Text 1. RenderBefore is DEF'd once and USEd 3 times -> 4
    // instances: ILS 12, PointSet 8, Text 4. Each PointSet is `coord USE KrzyzykCoord`, the
    // 4 points `-2 0 0, 2 0 0, 0 0 -2, 0 0 2` -> 8 x 4 = 32 spheres (Material emissiveColor
    // only, no transparency -> 0 gas). Plus Cylinder 2 (DEF cyl1, the `side FALSE` last one),
    // Cone 2 (DEF cone1 `side FALSE`, one inline) as surfaces and WorldInfo 1. No
    // Sphere/light/Viewpoint (the trailing Viewpoint is commented out).
    Expected {
        path: "conformance/castle-demo-models/vrml_2/cones_gzipped_but_with_normal_extension.wrl",
        spheres: 32,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 2,
        cones: 2,
        triangles: 0,
        skipped: &[("IndexedLineSet", 12), ("Text", 4), ("WorldInfo", 1)],
    },
    // `Inline { url "groundPlane.wrl" }` (exists next to it): Transform{DirectionalLight,
    // 3 Shapes with IndexedFaceSet} -> DirectionalLight 1 and, read by hand: ground plane
    // `coordIndex [ 0 1 2 3 -1 ]` (1 quad -> 2 triangles), flag pole `[ 0 1 4 3 -1 1 2 5 4 -1
    // 2 0 3 5 -1 3 4 5 -1 ]` (3 quads + 1 triangle -> 7), flag `[ 0 1 2 3 -1 ]` (-> 2): all
    // have < 12 points, so no sphere -> 11 triangles. Own content: Viewpoint 1, Box 1,
    // Cone 1, Sphere 1. Nothing skipped.
    Expected {
        path: "conformance/openvrml/models/Inline.wrl",
        spheres: 1,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 1,
        cylinders: 0,
        cones: 1,
        triangles: 11,
        skipped: &[],
    },
    // WorldInfo 1, Viewpoint 1, PointLight 3 (top level); Transform{Shape{IndexedLineSet}};
    // DEF myBox Transform{Box}; 3 axis Transforms each with a DEF mySphereX/Y/Z Transform{Sphere}
    // and a PlaneSensor (X, Y beside the sphere Transform, Z inside it) -> 3 spheres,
    // PlaneSensor 3; DEF myMoverScript Script 1; 7 ROUTEs ignored. `grep -c Box` = 1, never
    // USEd (`USE myBox` absent) -> boxes 1.
    Expected {
        path: "conformance/freewrl/freewrl/tests/48.wrl",
        spheres: 3,
        gas: 0,
        point_lights: 3,
        directional_lights: 0,
        viewpoints: 1,
        boxes: 1,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[
            ("IndexedLineSet", 1),
            ("PlaneSensor", 3),
            ("Script", 1),
            ("WorldInfo", 1),
        ],
    },
    // Shape{Box} at top level (-> boxes 1); Transform{Shape{Sphere}, Transform{scale 1 3 1,
    // Shape{Sphere}}}. Nothing skipped.
    Expected {
        path:
            "conformance/castle-demo-models/vrml_engine_doc_simple_examples/transform_accum_1.wrl",
        spheres: 2,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 1,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // Transform{Transform{PointLight, Shape{PointSet}}} (the transparent radius Sphere is
    // commented out); Viewpoint 1; DEF Row Group of 3 sphere Shapes (DEF App / USE App
    // appearances) instanced once by DEF and twice by `USE Row` -> 3 x 3 = 9 spheres. The
    // PointSet (`coord Coordinate { point 0 0 0 }`, a single point, no appearance -> unlit,
    // opaque) adds 1 sphere -> 10; nothing skipped.
    Expected {
        path: "conformance/castle-demo-models/castle-anim-frames/simple/specular_demo_1.wrl",
        spheres: 10,
        gas: 0,
        point_lights: 1,
        directional_lights: 0,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // 3 `Button` PROTO instances (geom Box / Sphere / Cone). Each expands to Group{
    // DEF TOS TouchSensor, DEF Toggle Script, DEF SW Switch{whichChoice 0, choice[Shape{
    // geometry IS geom}, ...]}} -> per instance TouchSensor 1, Script 1 and the geom once.
    // Plus DEF ThreeButtons Script (1) and DEF T Transform{Shape{Sphere, no appearance},
    // PositionInterpolator, TimeSensor, NavigationInfo}. Spheres: B2 + T = 2; surfaces Box 1
    // (B1's geom), Cone 1 (B3's geom); Script 3 + 1 = 4; TouchSensor 3.
    Expected {
        path: "conformance/freewrl/freewrl/tests/SAIClick/testscript.wrl",
        spheres: 2,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 1,
        cylinders: 0,
        cones: 1,
        triangles: 0,
        skipped: &[
            ("PositionInterpolator", 1),
            ("Script", 4),
            ("TimeSensor", 1),
            ("TouchSensor", 3),
        ],
    },
    // Two Switches with `whichChoice 1` over [Box, Cone, Sphere, Cylinder] -> only the Cone
    // in each (the Spheres are choice 2, not drawn) -> cones 2 (Box/Cylinder choices not
    // drawn -> 0). DEF Clock TimeSensor 1, DEF SCRIPT Script 1.
    Expected {
        path: "conformance/freewrl/freewrl/tests/Javascript_tests/SFInt32.wrl",
        spheres: 0,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 2,
        triangles: 0,
        skipped: &[("Script", 1), ("TimeSensor", 1)],
    },
    // DEF V1 Viewpoint (1). Group: Shape whose geometry is `DEF CURSOR_1 Cursor {...}`, a
    // PROTO declared in the file whose first body node is IndexedLineSet -> expanded ->
    // IndexedLineSet 1 (reading: PROTO expansion applies to geometry nodes too; a reader
    // that did not expand would report "Cursor" instead); Shape{Sphere} with
    // `material DEF mat Material{transparency 0.05}` -> 1 sphere, gas; Cylinder 1 (transparency
    // 0.0) and Transform{Box} 1 -> surfaces; Billboard{Transform{Shape{Text}}} -> Text 1.
    // Top level:
    // DEF O1 OSC_Sensor (non-standard node) 1, DEF joystickController Script 1.
    Expected {
        path: "conformance/freewrl/freewrl/tests/18-OSC-jZoom-4.wrl",
        spheres: 1,
        gas: 1,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 1,
        boxes: 1,
        cylinders: 1,
        cones: 0,
        triangles: 0,
        skipped: &[
            ("IndexedLineSet", 1),
            ("OSC_Sensor", 1),
            ("Script", 1),
            ("Text", 1),
        ],
    },
    // Own: Viewpoint 3, red Sphere 1, Box 1, and `Inline { url ["helpers/blimp.wrl"] }`.
    // blimp.wrl: Group{ TimeSensor 1, OrientationInterpolator 1, Transform{Transform{
    // dirigible{}}} }; dirigible expands to Group{ hull Sphere 1, DEF horizontalFins Cone 1
    // + USE horizontalFins Cone 1, DEF pilotView Viewpoint 1, `Inline { url ["can.wrl"] }`
    // resolved relative to helpers/ } ; can.wrl: 3 Shapes with Cylinder + ImageTexture each.
    // Totals: spheres 2, Viewpoints 4; surfaces Box 1, Cone 2, Cylinder 3; skipped
    // ImageTexture 3, OrientationInterpolator 1, TimeSensor 1.
    Expected {
        path: "conformance/freewrl/freewrl/tests/16.wrl",
        spheres: 2,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 4,
        boxes: 1,
        cylinders: 3,
        cones: 2,
        triangles: 0,
        skipped: &[
            ("ImageTexture", 3),
            ("OrientationInterpolator", 1),
            ("TimeSensor", 1),
        ],
    },
    // Inline chain: relative_names.wrl -> subdir1/relative_inline2.wrl -> (relative to subdir1)
    // subdir2/texture_test.wrl. texture_test: Cone, Cylinder, Sphere share DEF TexApp
    // Appearance (ImageTexture DEF TexTest) -> ImageTexture 3; Box Shape with TextureTransform
    // + USE TexTest -> TextureTransform 1, ImageTexture 1; IFS Shape with USE TexTest ->
    // ImageTexture 1; last Shape Sphere. Spheres 2; ImageTexture 5. Surfaces: Cone 1,
    // Cylinder 1, Box 1; the IFS has 5 points and `coordIndex [0, 1, 2, 3, 4]` (one convex
    // pentagon, no trailing -1) -> 5 - 2 = 3 triangles.
    Expected {
        path: "conformance/castle-demo-models/vrml_2/relative_names.wrl",
        spheres: 2,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 1,
        cylinders: 1,
        cones: 1,
        triangles: 3,
        skipped: &[("ImageTexture", 5), ("TextureTransform", 1)],
    },
    // One Shape{geometry Sphere, appearance Appearance{material RefractiveMaterial{...}}}
    // where RefractiveMaterial is an EXTERNPROTO: its urls are "urn:inet:foo.com:..." (not
    // local: skipped) and "RefractiveMaterial.wrl", which is beside it and declares PROTO
    // RefractiveMaterial (the first PROTO of that file) with a body of one Material. So the
    // instance is that Material (modelled, not counted) and nothing is skipped; the
    // EXTERNPROTO's seven exposedFields match the PROTO's; the instance's `transparency` is
    // not given and the default is 0 -> opaque. RefractiveMaterial.wrl has no top-level node.
    Expected {
        path: "conformance/openvrml/models/ExternPROTO.wrl",
        spheres: 1,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // Three EXTERNPROTOs naming proto_nodes.wrl (beside it): "proto_nodes.wrl" (its first
    // PROTO, MaterialSphere), "#MaterialSphereDefaultRed" and "#MaterialSphereDefaultYellow";
    // 2 instances of each at top level, each body a Shape{Sphere} -> 6 spheres. The Text
    // labels of proto_nodes.wrl are its top-level nodes: not drawn here. No transparency
    // anywhere (the DefaultYellow default `material USE YellowMat` is a DEF of
    // proto_nodes.wrl, diffuseColor 1 1 0). No lights or viewpoints in either file.
    Expected {
        path: "conformance/castle-demo-models/prototypes/proto_nodes_by_external.wrl",
        spheres: 6,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // EXTERNPROTO StrawberryGroup: "not_existing.wrl" (no such file) and two urns (not
    // local); EXTERNPROTO CherryShape: one urn. Neither loads, and the whole scene is one
    // top-level StrawberryGroup instance -> skipped once; what is inside it (the CherryShape
    // instances, the Switch, the Transforms) is not walked. Nothing drawn.
    Expected {
        path: "conformance/castle-demo-models/prototypes/extern_proto_built_in_kings_head.wrl",
        spheres: 0,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[("StrawberryGroup", 1)],
    },
    // `BouncingShape { appearance ..., geometry Sphere{} }` -> PROTO body DEF bounceTrans
    // Transform{ Shape{appearance IS, geometry IS} (Sphere 1), PositionInterpolator 1,
    // TimeSensor 1 }; ROUTEs inside the PROTO body ignored.
    Expected {
        path: "conformance/openvrml/models/bounce.wrl",
        spheres: 1,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[("PositionInterpolator", 1), ("TimeSensor", 1)],
    },
    // WorldInfo 1, DEF SENSOR ProximitySensor 1 (top level). Transform{DirectionalLight,
    // Cone, Cylinder, Collision{children Sphere}, Box}; DEF HUDVIEW Viewpoint 1;
    // DEF HUD Transform{Collision{children DirectionalLight, Transform{Box}}}.
    // -> Sphere 1, DirectionalLight 2; surfaces Box 2, Cone 1, Cylinder 1.
    Expected {
        path: "conformance/freewrl/freewrl/tests/collision.wrl",
        spheres: 1,
        gas: 0,
        point_lights: 0,
        directional_lights: 2,
        viewpoints: 1,
        boxes: 2,
        cylinders: 1,
        cones: 1,
        triangles: 0,
        skipped: &[("ProximitySensor", 1), ("WorldInfo", 1)],
    },
    // `DEF MyInline Inline { url "reuse_cone.wrl" }` + 4 nested Transforms each with
    // `USE MyInline` -> 5 Inline instances; reuse_cone.wrl has 2 Shapes with Cone
    // (DEF NamedCone + USE NamedCone) -> 5 x 2 = 10 Cone surfaces; nothing skipped.
    Expected {
        path: "conformance/castle-demo-models/vrml_engine_doc_simple_examples/inline.wrl",
        spheres: 0,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 10,
        triangles: 0,
        skipped: &[],
    },
    // `EXTERNPROTO UnrecognizedNode [...] ["urn:unrecognized"]` + one top-level instance
    // -> skipped under the EXTERNPROTO's declared name.
    Expected {
        path: "conformance/openvrml/tests/vrml97/good/unrecognized-externproto.wrl",
        spheres: 0,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[("UnrecognizedNode", 1)],
    },
];

//! The scene IR: only what a picture needs (docs/model.md section 1). Knows nothing of VRML.

mod build;
mod color;
mod material_table;
pub(crate) mod profile;
mod surface;

use glam::{DAffine3, DQuat, DVec3};

pub use build::{Radii, SphereArrays};
pub use color::{Color, Colors};
pub use material_table::{MaterialTable, Paint};
pub use profile::{Profile, ProfileError, DEFAULT_WIDTH};
pub(crate) use surface::Mapping;
pub use surface::{Surface, SurfaceCounts, SurfaceShape, Triangle};

/// Index of an ellipsoid's map in [`Scene::ellipsoids`] (and in the BVH's copy of them),
/// stored plus one so that `Option<EllipsoidId>`, "a true sphere" when `None`, is 4 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EllipsoidId(std::num::NonZeroU32);

impl EllipsoidId {
    /// The id of `ellipsoids[index]`; `None` past `u32::MAX - 1` ellipsoids.
    pub fn new(index: usize) -> Option<EllipsoidId> {
        let stored = u32::try_from(index).ok()?.checked_add(1)?;
        std::num::NonZeroU32::new(stored).map(EllipsoidId)
    }

    /// Its index into the ellipsoids.
    #[inline]
    pub fn index(self) -> usize {
        (self.0.get() - 1) as usize
    }
}

/// Where an IR item came from: file index into [`Scene::files`] and byte offset, packed in
/// one word (a sphere is then 56 bytes, not 64). Indices past 2^20 - 1 files and offsets
/// past 2^44 - 1 bytes (16 TiB) are stored as those maxima. [`Scene::position`] turns it into
/// `file:line:col` when an error found after loading must point into the file; kept rather
/// than dropped because that costs 8 bytes per item and no line index.
#[derive(Clone, Copy, PartialEq, Eq, Default)]
pub struct Origin(u64);

impl Origin {
    const OFFSET_BITS: u32 = 44;
    const MAX_OFFSET: u64 = (1 << Self::OFFSET_BITS) - 1;
    const MAX_FILE: u32 = (1 << (64 - Self::OFFSET_BITS)) - 1;

    /// The origin of byte `offset` in file `file`, each capped at its maximum (see [`Origin`]).
    pub fn new(file: u32, offset: u64) -> Self {
        let file = u64::from(file.min(Self::MAX_FILE));
        Origin(file << Self::OFFSET_BITS | offset.min(Self::MAX_OFFSET))
    }

    /// Index into [`Scene::files`].
    pub fn file(self) -> u32 {
        (self.0 >> Self::OFFSET_BITS) as u32
    }

    /// Byte offset in that file.
    pub fn offset(self) -> u64 {
        self.0 & Self::MAX_OFFSET
    }
}

impl std::fmt::Debug for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Origin")
            .field("file", &self.file())
            .field("offset", &self.offset())
            .finish()
    }
}

/// A sphere in world space. For an ellipsoid (non-uniform scale), `ellipsoid` indexes
/// [`Scene::ellipsoids`], the affine map from the unit sphere to the world, and `center`/`radius`
/// are its centre and a bounding radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Its centre, in world space.
    pub center: DVec3,
    /// Its radius in world units, positive and finite; for an ellipsoid, a radius about `center`
    /// that bounds it.
    pub radius: f64,
    /// Its diffuse colour (see [`MaterialTable`]).
    pub color: Color,
    /// Index of its material's record in [`Scene::materials`] (all but the diffuse colour).
    pub material: u32,
    /// `None` for a true sphere.
    pub ellipsoid: Option<EllipsoidId>,
    /// Where in the input it was defined.
    pub origin: Origin,
}

impl Sphere {
    /// What it refers to in [`Scene::materials`].
    #[inline]
    pub fn paint(&self) -> Paint {
        Paint {
            material: self.material,
            color: self.color,
        }
    }
}

/// VRML97 Material (with VRML defaults), or the unlit white of a Shape without one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// `diffuseColor`: RGB reflectance of a surface, or the scattering albedo of gas; each
    /// channel at least 0.
    pub diffuse: DVec3,
    /// `emissiveColor`: RGB radiance a surface gives off by itself, or the emission colour of
    /// gas (emitted per unit optical depth); each channel at least 0.
    pub emissive: DVec3,
    /// `specularColor`: RGB weight of the specular highlight, each channel at least 0.
    pub specular: DVec3,
    /// `shininess`, in [0, 1]: the Phong exponent is 128 times it.
    pub shininess: f64,
    /// `ambientIntensity`: how much of the lights' ambient term it reflects, at least 0.
    pub ambient_intensity: f64,
    /// `transparency`, in [0, 1]: 0 is opaque; above 0 makes a sphere that is not unlit gas,
    /// whose transmittance along a diameter it is (see [`Material::sigma`]).
    pub transparency: f64,
    /// A Shape with no Appearance or no Material: colour (1,1,1), lights ignored (VRML 4.14.2).
    pub unlit: bool,
    /// The density profile of a gas sphere of this material (docs/model.md section 6; a
    /// `GasParticle` PROTO instance sets it); opaque spheres ignore it.
    pub profile: Profile,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            diffuse: DVec3::splat(0.8),
            emissive: DVec3::ZERO,
            specular: DVec3::ZERO,
            shininess: 0.2,
            ambient_intensity: 0.2,
            transparency: 0.0,
            unlit: false,
            profile: Profile::Constant,
        }
    }
}

impl Material {
    /// Unlit white. An unlit material glows its `diffuse` colour (white unless a mesh's
    /// Color node gives its colours, VRML 4.14.2).
    pub fn unlit() -> Self {
        Material {
            diffuse: DVec3::ONE,
            unlit: true,
            ..Material::default()
        }
    }
    /// Every field's bits: materials are equal when their keys are (so `-0.0` and `0.0`
    /// differ, as they would be printed differently).
    pub fn key(&self) -> [u64; 15] {
        [
            self.diffuse.x.to_bits(),
            self.diffuse.y.to_bits(),
            self.diffuse.z.to_bits(),
            self.emissive.x.to_bits(),
            self.emissive.y.to_bits(),
            self.emissive.z.to_bits(),
            self.specular.x.to_bits(),
            self.specular.y.to_bits(),
            self.specular.z.to_bits(),
            self.shininess.to_bits(),
            self.ambient_intensity.to_bits(),
            self.transparency.to_bits(),
            self.unlit as u64,
            self.profile.key()[0],
            self.profile.key()[1],
        ]
    }
    /// Gas: `0 < transparency <= 1` (docs/model.md section 1).
    pub fn is_gas(&self) -> bool {
        !self.unlit && self.transparency > 0.0
    }
    /// Extinction of a gas sphere of radius `r`: transmittance along a diameter equals transparency.
    pub fn sigma(&self, r: f64) -> f64 {
        -self.transparency.ln() / (2.0 * r)
    }
}

/// VRML97 PointLight: light from a point, in every direction, out to `radius`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Its position, in world space.
    pub location: DVec3,
    /// RGB colour of its light, each channel at least 0.
    pub color: DVec3,
    /// Brightness multiplying `color` for direct light, at least 0.
    pub intensity: f64,
    /// Brightness multiplying `color` for the ambient term, at least 0.
    pub ambient_intensity: f64,
    /// Coefficients `(a0, a1, a2)`: at distance `d` the light is scaled by
    /// `1 / max(a0 + a1 d + a2 d^2, 1)`.
    pub attenuation: DVec3,
    /// Distance beyond which it lights nothing, in world units, not negative.
    pub radius: f64,
    /// Whether it shines; a light that is off contributes nothing.
    pub on: bool,
    /// Where in the input it was defined.
    pub origin: Origin,
}

/// VRML97 DirectionalLight: parallel light from infinitely far away, lighting only its scope.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction the light travels in (world space).
    pub direction: DVec3,
    /// RGB colour of its light, each channel at least 0.
    pub color: DVec3,
    /// Brightness multiplying `color` for direct light, at least 0.
    pub intensity: f64,
    /// Brightness multiplying `color` for the ambient term, at least 0.
    pub ambient_intensity: f64,
    /// Whether it shines; a light that is off contributes nothing.
    pub on: bool,
    /// The spheres it lights (VRML scoping).
    pub scope: LightScope,
    /// The surfaces it lights (indices into [`Scene::surfaces`]).
    pub surface_scope: LightScope,
    /// Where in the input it was defined.
    pub origin: Origin,
}

/// What a DirectionalLight lights (VRML97 4.6.7: its siblings in the enclosing grouping node
/// and their descendants): one range of the IR's spheres, and one of its surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightScope {
    /// Everything of the scene (a light built in code, the headlight).
    All,
    /// `Scene::spheres[start..end]` (or `Scene::surfaces[start..end]`).
    Range {
        /// The first index lit.
        start: u32,
        /// One past the last index lit; `start == end` lights nothing.
        end: u32,
    },
}

impl LightScope {
    /// Whether it lights sphere `sphere` (an index into [`Scene::spheres`]).
    #[inline]
    pub fn contains(self, sphere: u32) -> bool {
        match self {
            LightScope::All => true,
            LightScope::Range { start, end } => start <= sphere && sphere < end,
        }
    }

    /// The indices it lights in a scene of `n` spheres, `start .. end`.
    pub fn range(self, n: usize) -> (u32, u32) {
        match self {
            LightScope::All => (0, u32::try_from(n).unwrap_or(u32::MAX)),
            LightScope::Range { start, end } => (start, end),
        }
    }

    /// Whether it lights every one of `n` spheres.
    pub fn covers_all(self, n: usize) -> bool {
        let (start, end) = self.range(n);
        start == 0 && end as usize >= n
    }
}

impl Default for PointLight {
    /// VRML97's PointLight defaults: at the origin, white, intensity 1, ambientIntensity 0,
    /// attenuation (1, 0, 0), radius 100, on.
    fn default() -> Self {
        PointLight {
            location: DVec3::ZERO,
            color: DVec3::ONE,
            intensity: 1.0,
            ambient_intensity: 0.0,
            attenuation: DVec3::new(1.0, 0.0, 0.0),
            radius: 100.0,
            on: true,
            origin: Origin::default(),
        }
    }
}

impl Default for DirectionalLight {
    /// VRML97's DirectionalLight defaults (direction (0, 0, -1), white, intensity 1,
    /// ambientIntensity 0, on), lighting the whole scene: a light built in code has no
    /// grouping node to scope it.
    fn default() -> Self {
        DirectionalLight {
            direction: DVec3::new(0.0, 0.0, -1.0),
            color: DVec3::ONE,
            intensity: 1.0,
            ambient_intensity: 0.0,
            on: true,
            scope: LightScope::All,
            surface_scope: LightScope::All,
            origin: Origin::default(),
        }
    }
}

/// A light of the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A point light.
    Point(PointLight),
    /// A directional light.
    Directional(DirectionalLight),
}

/// VRML97 Viewpoint: a camera position and orientation the scene offers.
#[derive(Clone, Debug, PartialEq)]
pub struct Viewpoint {
    /// DEF name, if any.
    pub name: Option<String>,
    /// Its `description` text, empty if none was given.
    pub description: String,
    /// The eye's position, in world space.
    pub position: DVec3,
    /// Rotation from the default view (looking down -z with +y up) to its view.
    pub orientation: DQuat,
    /// Angle of the smaller image side, radians.
    pub field_of_view: f64,
    /// Where in the input it was defined.
    pub origin: Origin,
}

impl Default for Viewpoint {
    /// VRML97's Viewpoint defaults: at (0, 0, 10) looking down -z, fieldOfView pi/4.
    fn default() -> Self {
        Viewpoint {
            name: None,
            description: String::new(),
            position: DVec3::new(0.0, 0.0, 10.0),
            orientation: DQuat::IDENTITY,
            field_of_view: std::f64::consts::FRAC_PI_4,
            origin: Origin::default(),
        }
    }
}

/// Everything a picture needs: spheres (opaque or gas), other opaque surfaces, materials,
/// lights and viewpoints, each item remembering where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The spheres and ellipsoids, opaque or gas, in input order.
    pub spheres: Vec<Sphere>,
    /// Affine maps from the unit sphere to the world, indexed by [`Sphere::ellipsoid`].
    pub ellipsoids: Vec<DAffine3>,
    /// Opaque surfaces other than spheres: Box, Cylinder, Cone, triangles.
    pub surfaces: Vec<Surface>,
    /// The material records that spheres and surfaces refer to.
    pub materials: MaterialTable,
    /// The lights, in input order (the headlight is not among them).
    pub lights: Vec<Light>,
    /// The viewpoints, in input order (VRML binds the first at start).
    pub viewpoints: Vec<Viewpoint>,
    /// NavigationInfo.headlight of the first NavigationInfo (default TRUE).
    pub headlight: bool,
    /// `Background.skyColor[0]` of the first Background (default black).
    pub background: DVec3,
    /// Source file names, indexed by [`Origin::file`].
    pub files: Vec<String>,
}

impl Default for Scene {
    fn default() -> Self {
        Scene {
            spheres: Vec::new(),
            ellipsoids: Vec::new(),
            surfaces: Vec::new(),
            materials: MaterialTable::new(),
            lights: Vec::new(),
            viewpoints: Vec::new(),
            headlight: true,
            background: DVec3::ZERO,
            files: Vec::new(),
        }
    }
}

/// Axis-aligned bounds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Bounds {
    /// Smallest x, y and z.
    pub min: [f64; 3],
    /// Largest x, y and z.
    pub max: [f64; 3],
}

impl Scene {
    /// The material of sphere `s`.
    #[inline]
    pub fn material_of(&self, s: &Sphere) -> Material {
        self.materials.get(s.material, s.color)
    }

    /// The material of surface `s`.
    #[inline]
    pub fn surface_material(&self, s: &Surface) -> Material {
        self.materials.get(s.material, s.color)
    }

    /// Appends a sphere of material `m` (its record shared with equal ones).
    pub fn add_sphere(&mut self, center: DVec3, radius: f64, m: &Material) {
        let Paint { material, color } = self.materials.add(m);
        self.spheres.push(Sphere {
            center,
            radius,
            color,
            material,
            ellipsoid: None,
            origin: Origin::default(),
        });
    }

    /// Gas spheres whose density profile is not constant (docs/model.md section 6).
    pub fn profiled_gas_count(&self) -> usize {
        if !self.materials.may_have_profiled_gas() {
            return 0;
        }
        self.spheres
            .iter()
            .filter(|s| {
                let m = self.materials.record(s.material);
                m.is_gas() && m.profile != Profile::Constant
            })
            .count()
    }

    /// The number of gas spheres (see [`Material::is_gas`]).
    pub fn gas_count(&self) -> usize {
        if !self.materials.may_have_gas() {
            return 0;
        }
        self.spheres
            .iter()
            .filter(|s| self.materials.record(s.material).is_gas())
            .count()
    }
    /// The number of spheres that are ellipsoids.
    pub fn ellipsoid_count(&self) -> usize {
        self.spheres
            .iter()
            .filter(|s| s.ellipsoid.is_some())
            .count()
    }
    /// The number of point lights, on or off.
    pub fn point_light_count(&self) -> usize {
        self.lights
            .iter()
            .filter(|l| matches!(l, Light::Point(_)))
            .count()
    }
    /// The number of directional lights, on or off.
    pub fn directional_light_count(&self) -> usize {
        self.lights.len() - self.point_light_count()
    }
    /// The surfaces by kind.
    pub fn surface_counts(&self) -> SurfaceCounts {
        SurfaceCounts::of(&self.surfaces)
    }
    /// Drops every surface that is not a sphere (`--spheres-only`); light scopes of surfaces
    /// become empty.
    pub fn drop_surfaces(&mut self) {
        self.surfaces = Vec::new();
        for l in &mut self.lights {
            if let Light::Directional(d) = l {
                d.surface_scope = LightScope::Range { start: 0, end: 0 };
            }
        }
    }

    /// World bounds of all spheres (exact for ellipsoids) and surfaces, or None for an empty
    /// scene.
    pub fn bounds(&self) -> Option<Bounds> {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for s in &self.spheres {
            let half = match s.ellipsoid {
                None => DVec3::splat(s.radius),
                Some(e) => {
                    // Half extent along world axis i of A(unit sphere) is the norm of row i.
                    let m = self.ellipsoids[e.index()].matrix3;
                    DVec3::new(m.row(0).length(), m.row(1).length(), m.row(2).length())
                }
            };
            lo = lo.min(s.center - half);
            hi = hi.max(s.center + half);
        }
        for s in &self.surfaces {
            let (a, b) = s.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        (lo.x <= hi.x).then(|| Bounds {
            min: lo.to_array(),
            max: hi.to_array(),
        })
    }

    /// Centre and radius of a ball holding every sphere (a bounding ball about the bounds'
    /// centre, not the smallest one), or None for an empty scene.
    pub fn bounding_ball(&self) -> Option<(DVec3, f64)> {
        Some(self.bounding_ball_in(self.bounds()?))
    }

    /// [`Scene::bounding_ball`] about the centre of `b`, the scene's [`Scene::bounds`] (for a
    /// caller that has them already: one pass over the spheres instead of two).
    pub(crate) fn bounding_ball_in(&self, b: Bounds) -> (DVec3, f64) {
        let c = DVec3::from(b.min) * 0.5 + DVec3::from(b.max) * 0.5;
        let r = self
            .spheres
            .iter()
            .map(|s| (s.center - c).length() + s.radius)
            .chain(self.surfaces.iter().map(|s| {
                let (centre, radius) = s.bounding_ball();
                (centre - c).length() + radius
            }))
            .fold(0.0, f64::max);
        (c, r)
    }

    /// Where `origin` points, as `file:line:col` (1-based line and byte column, as the
    /// loader's messages), for errors found after loading; the file is read again up to
    /// there. A source that is not a readable file (text
    /// loaded from memory, a file changed since) gives `name:byte OFFSET` instead.
    pub fn position(&self, origin: Origin) -> String {
        let name = self
            .files
            .get(origin.file() as usize)
            .map_or("<unknown source>", String::as_str);
        match crate::input::line_col_in(std::path::Path::new(name), origin.offset()) {
            Some((line, col)) => format!("{name}:{line}:{col}"),
            None => format!("{name}:byte {}", origin.offset()),
        }
    }

    /// Heap bytes held by the IR.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.spheres.capacity() * size_of::<Sphere>()
            + self.ellipsoids.capacity() * size_of::<DAffine3>()
            + self.surfaces.capacity() * size_of::<Surface>()
            + self
                .surfaces
                .iter()
                .map(|s| match s.shape {
                    SurfaceShape::Triangle(_) => size_of::<Triangle>(),
                    _ => 0,
                })
                .sum::<usize>()
            + self.materials.heap_bytes()
            + self.lights.capacity() * size_of::<Light>()
            + self.viewpoints.capacity() * size_of::<Viewpoint>()
            + self
                .viewpoints
                .iter()
                .map(|v| v.description.capacity() + v.name.as_ref().map_or(0, |n| n.capacity()))
                .sum::<usize>()
            + self.files.iter().map(|f| f.capacity()).sum::<usize>()
    }
}

/// The field of view of a framing camera (VRML's default, 45 degrees).
pub const FRAMING_FOV: f64 = std::f64::consts::FRAC_PI_4;

/// Where a camera looking down -z with [`FRAMING_FOV`] sees the ball `(centre, radius)` whole
/// (far enough that the ball fits the smaller side's angle), or `None` when it would stand
/// beyond the range of f64 (balls near +-1e308). The one framing rule of `render` (for a
/// scene without a Viewpoint) and of `convert` (the Viewpoint it writes).
pub fn framing_position(centre: DVec3, radius: f64) -> Option<DVec3> {
    let radius = radius.max(f64::MIN_POSITIVE);
    let position = centre + DVec3::new(0.0, 0.0, radius / (0.5 * FRAMING_FOV).sin());
    (position.is_finite() && radius.is_finite()).then_some(position)
}

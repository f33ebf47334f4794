//! Scenes built in code: spheres from arrays ([`Scene::from_arrays`]), and the checks every
//! scene passes before it is prepared ([`Scene::validate`]).

use glam::DVec3;

use super::{Light, Material, Origin, Scene};
use crate::Error;

/// Sphere radii: one for all, or one per centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Radii<'a> {
    /// The radius of every sphere, positive and finite.
    One(f64),
    /// One radius per sphere, each positive and finite.
    Each(&'a [f64]),
}

/// Spheres as arrays, the way particle data comes: `centers` holds `x, y, z` of sphere `i`
/// at `3 i .. 3 i + 3` (a `&[[f64; 3]]` gives it with `as_flattened()`), `colors` and
/// `emissive` likewise RGB in `[0, 1]`, `transparency` one value in `[0, 1]` per sphere
/// (0: opaque; otherwise gas whose diameter transmits that fraction, docs/model.md section 1).
/// Missing colours are VRML's default diffuse grey 0.8; missing emissive colours are black.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereArrays<'a> {
    /// Centres, `x, y, z` of sphere `i` at `3 i .. 3 i + 3`.
    pub centers: &'a [f64],
    /// The radii.
    pub radii: Radii<'a>,
    /// Diffuse RGB colours, three per sphere; `None`: grey 0.8.
    pub colors: Option<&'a [f64]>,
    /// Transparency, one per sphere; `None`: every sphere opaque.
    pub transparency: Option<&'a [f64]>,
    /// Emissive RGB colours, three per sphere; `None`: black.
    pub emissive: Option<&'a [f64]>,
}

impl<'a> SphereArrays<'a> {
    /// Opaque grey spheres.
    pub fn new(centers: &'a [f64], radii: Radii<'a>) -> Self {
        SphereArrays {
            centers,
            radii,
            colors: None,
            transparency: None,
            emissive: None,
        }
    }
}

fn triple(v: &[f64], i: usize) -> DVec3 {
    DVec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2])
}

fn bad(array: &str, index: usize, value: String, message: &str) -> Error {
    Error::Array {
        array: array.to_string(),
        index,
        value,
        message: message.to_string(),
    }
}

fn show3(v: DVec3) -> String {
    format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z)
}

/// Checks an RGB array: `3 n` values, each in `[0, 1]`.
fn check_rgb(name: &str, v: &[f64], n: usize) -> Result<(), Error> {
    if v.len() != 3 * n {
        return Err(Error::Invalid(format!(
            "{name} has {} values for {n} spheres; it needs 3 per sphere",
            v.len()
        )));
    }
    for i in 0..n {
        let c = triple(v, i);
        if !(c.cmpge(DVec3::ZERO).all() && c.cmple(DVec3::ONE).all()) {
            return Err(bad(name, i, show3(c), "colour channels must be in [0, 1]"));
        }
    }
    Ok(())
}

/// Finite, with no negative channel.
fn non_negative(c: DVec3) -> bool {
    c.is_finite() && c.cmpge(DVec3::ZERO).all()
}

impl Light {
    /// What is wrong with the light for rendering, if anything: finite non-negative colour,
    /// intensities and attenuation, a non-negative radius, a unit direction.
    pub fn problem(&self) -> Option<&'static str> {
        match self {
            Light::Point(p) => {
                if !p.location.is_finite() {
                    Some("the location is not finite")
                } else if !(non_negative(p.color)
                    && non_negative(DVec3::new(p.intensity, p.ambient_intensity, 0.0)))
                {
                    Some("colour and intensities must be finite and non-negative")
                } else if !non_negative(p.attenuation) {
                    Some("attenuation must be finite and non-negative")
                } else if p.radius.is_nan() || p.radius < 0.0 {
                    Some("radius must not be negative")
                } else {
                    None
                }
            }
            Light::Directional(d) => {
                if !(d.direction.is_finite() && (d.direction.length() - 1.0).abs() < 1e-9) {
                    Some("the direction must be a unit vector")
                } else if !(non_negative(d.color)
                    && non_negative(DVec3::new(d.intensity, d.ambient_intensity, 0.0)))
                {
                    Some("colour and intensities must be finite and non-negative")
                } else {
                    None
                }
            }
        }
    }

    /// Where the light came from.
    pub fn origin(&self) -> Origin {
        match self {
            Light::Point(p) => p.origin,
            Light::Directional(d) => d.origin,
        }
    }
}

impl Scene {
    /// A scene of the spheres in `arrays` (in that order, so `id` `i` is sphere `i`), with
    /// VRML's defaults for the rest: no lights but the headlight, black background, no
    /// Viewpoint. Every value is checked first; the first bad one is the error, naming the
    /// array, index and value (`radii[17] = -1: radius must be positive and finite`).
    ///
    /// Spheres with the same colour, transparency and emissive colour share one material.
    ///
    /// ```
    /// use gtsphere::scene::{Radii, Scene, SphereArrays};
    /// let centers = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    /// let scene = Scene::from_arrays(&SphereArrays::new(&centers, Radii::One(0.4))).unwrap();
    /// assert_eq!(scene.spheres.len(), 2);
    /// let err = Scene::from_arrays(&SphereArrays::new(&centers, Radii::Each(&[0.4, -1.0])));
    /// assert_eq!(
    ///     err.unwrap_err().to_string(),
    ///     "radii[1] = -1.0: radius must be positive and finite"
    /// );
    /// ```
    pub fn from_arrays(arrays: &SphereArrays) -> Result<Scene, Error> {
        let c = arrays.centers;
        if c.len() % 3 != 0 {
            return Err(Error::Invalid(format!(
                "centers has {} values, not 3 per sphere",
                c.len()
            )));
        }
        let n = c.len() / 3;
        if u32::try_from(n).is_err() {
            return Err(Error::Invalid(format!(
                "{n} spheres: at most {} are supported",
                u32::MAX
            )));
        }
        for i in 0..n {
            let p = triple(c, i);
            if !p.is_finite() {
                return Err(bad("centers", i, show3(p), "the centre must be finite"));
            }
        }
        let radius_ok = |r: f64| r > 0.0 && r.is_finite();
        match arrays.radii {
            Radii::One(r) if !radius_ok(r) => {
                return Err(Error::Invalid(format!(
                    "radius = {r:?}: radius must be positive and finite"
                )))
            }
            Radii::Each(r) if r.len() != n => {
                return Err(Error::Invalid(format!(
                    "radii has {} values for {n} centres",
                    r.len()
                )))
            }
            Radii::Each(r) => {
                if let Some(i) = r.iter().position(|&x| !radius_ok(x)) {
                    return Err(bad(
                        "radii",
                        i,
                        format!("{:?}", r[i]),
                        "radius must be positive and finite",
                    ));
                }
            }
            Radii::One(_) => {}
        }
        if let Some(v) = arrays.colors {
            check_rgb("colors", v, n)?;
        }
        if let Some(v) = arrays.emissive {
            check_rgb("emissive", v, n)?;
        }
        if let Some(t) = arrays.transparency {
            if t.len() != n {
                return Err(Error::Invalid(format!(
                    "transparency has {} values for {n} centres",
                    t.len()
                )));
            }
            if let Some(i) = t.iter().position(|x| !(0.0..=1.0).contains(x)) {
                return Err(bad(
                    "transparency",
                    i,
                    format!("{:?}", t[i]),
                    "transparency must be in [0, 1]",
                ));
            }
        }

        let mut scene = Scene::default();
        scene.spheres.reserve_exact(n);
        for i in 0..n {
            let mut m = Material::default();
            if let Some(v) = arrays.colors {
                m.diffuse = triple(v, i);
            }
            if let Some(v) = arrays.emissive {
                m.emissive = triple(v, i);
            }
            if let Some(t) = arrays.transparency {
                m.transparency = t[i];
            }
            let radius = match arrays.radii {
                Radii::One(r) => r,
                Radii::Each(r) => r[i],
            };
            scene.add_sphere(triple(c, i), radius, &m);
        }
        Ok(scene)
    }

    /// Checks what rendering relies on, for scenes however built: spheres with finite
    /// centres, positive finite radii and materials that exist; materials with finite
    /// non-negative colours and transparency in `[0, 1]`; lights with finite non-negative
    /// colours and intensities, unit directions and non-negative attenuation; Viewpoints
    /// with finite positions; a finite non-negative background. The error names the item:
    /// its `file:line:col` when it came from a file, else `spheres[i]`, `lights[i]`, ...
    pub fn validate(&self) -> Result<(), Error> {
        let at = |what: &str, i: usize, origin: Origin| -> String {
            if self.files.is_empty() {
                format!("{what}[{i}]")
            } else {
                self.position(origin)
            }
        };
        let fail = |m: String| Err(Error::Invalid(m));
        for (i, s) in self.spheres.iter().enumerate() {
            if !s.center.is_finite() {
                return fail(format!(
                    "{}: the centre {} is not finite",
                    at("spheres", i, s.origin),
                    show3(s.center)
                ));
            }
            if !(s.radius > 0.0 && s.radius.is_finite()) {
                return fail(format!(
                    "{}: radius {:?} must be positive and finite",
                    at("spheres", i, s.origin),
                    s.radius
                ));
            }
            if s.material as usize >= self.materials.len() {
                return fail(format!(
                    "spheres[{i}]: material {} does not exist ({} materials)",
                    s.material,
                    self.materials.len()
                ));
            }
            if !self.materials.holds(s.color) {
                return fail(format!(
                    "spheres[{i}]: its colour {:?} is not in the scene's materials",
                    s.color
                ));
            }
            if let Some(e) = s.ellipsoid {
                if e.index() >= self.ellipsoids.len() {
                    return fail(format!(
                        "spheres[{i}]: ellipsoid {} does not exist",
                        e.index()
                    ));
                }
            }
        }
        for (i, m) in self.materials.records().iter().enumerate() {
            let scalars_ok = [m.shininess, m.ambient_intensity]
                .iter()
                .all(|x| x.is_finite() && *x >= 0.0);
            if !(non_negative(m.emissive) && non_negative(m.specular) && scalars_ok) {
                return fail(format!(
                    "materials[{i}]: colours, shininess and ambientIntensity must be finite \
                     and non-negative"
                ));
            }
            if !(0.0..=1.0).contains(&m.transparency) {
                return fail(format!(
                    "materials[{i}]: transparency {:?} must be in [0, 1]",
                    m.transparency
                ));
            }
        }
        // Packed colours are finite and non-negative; only listed ones are looked at.
        if !self
            .materials
            .listed_colors()
            .iter()
            .all(|&c| non_negative(c))
        {
            let colour = |c| self.materials.diffuse(c);
            let bad = |c| !non_negative(colour(c));
            let found = (self.spheres.iter().enumerate())
                .find(|(_, s)| bad(s.color))
                .map(|(i, s)| (at("spheres", i, s.origin), colour(s.color)))
                .or_else(|| {
                    (self.surfaces.iter().enumerate())
                        .find(|(_, s)| bad(s.color))
                        .map(|(i, s)| (at("surfaces", i, s.origin), colour(s.color)))
                });
            if let Some((at, c)) = found {
                return fail(format!(
                    "{at}: the diffuse colour {} must be finite and non-negative",
                    show3(c)
                ));
            }
        }
        for (i, l) in self.lights.iter().enumerate() {
            if let Some(m) = l.problem() {
                return fail(format!("{}: {m}", at("lights", i, l.origin())));
            }
        }
        for (i, v) in self.viewpoints.iter().enumerate() {
            if !(v.position.is_finite() && v.orientation.is_finite()) {
                return fail(format!(
                    "{}: position and orientation must be finite",
                    at("viewpoints", i, v.origin)
                ));
            }
        }
        if !non_negative(self.background) {
            return fail(format!(
                "the background {} must be finite and non-negative",
                show3(self.background)
            ));
        }
        Ok(())
    }
}

//! Particles out as VRML97, one row at a time: a `PROTO Particle` declared once and one
//! compact instance per particle (or, with `plain`, ordinary Transform/Shape/Sphere nodes),
//! then a framing Viewpoint and lights at the end, where the bounds are known.
//!
//! The PROTO is standard VRML97: browsers that know nothing of gtsphere show ordinary
//! spheres. A gas particle's density sigma becomes the Material's transparency
//! `exp(-2 r sigma)` (docs/model.md section 1), so reading the file back gives
//! `sigma = -ln(transparency) / (2 r)`; the transparency reads back as the same f64, so that
//! loses nothing above optical depths `2 r sigma` of about 1e-16 relative to 1 (a diameter
//! of optical depth `tau` comes back with relative error about `1e-16 / tau`).
//!
//! Positions, radii and 0-1 colours read as numbers are written back as the very text they
//! were read from (when it has no decimal comma); every other number by the one rule of
//! [`crate::vrml::number`], the same as `convert` of a scene.

use std::io::{self, Write};

use glam::DVec3;

use super::read::{Num, Particle};
use crate::scene::Profile;
use crate::vrml::number;

/// The PROTO every instance refers to; `radius` defaults to `--radius` when given. With
/// `profiles`, it is the `GasParticle` the reader recognises (`crate::vrml` reads its
/// `profile` and `width` fields; other viewers show the same spheres).
fn proto(default_radius: f64, profiles: bool) -> String {
    let mut buf = ryu::Buffer::new();
    let (name, extra) = if profiles {
        (
            "GasParticle",
            "\n  field SFString profile \"constant\"\n  field SFFloat width 0.3333333333333333",
        )
    } else {
        ("Particle", "")
    };
    format!(
        "PROTO {name} [\n  field SFVec3f position 0 0 0\n  field SFFloat radius {}\n  field SFColor color 0.8 0.8 0.8\n  field SFColor emission 0 0 0\n  field SFFloat transparency 0{extra}\n] {{\n  Transform {{\n    translation IS position\n    children Shape {{\n      appearance Appearance {{\n        material Material {{ diffuseColor IS color emissiveColor IS emission transparency IS transparency }}\n      }}\n      geometry Sphere {{ radius IS radius }}\n    }}\n  }}\n}}\n",
        number::format(&mut buf, default_radius)
    )
}

/// What to add after the particles.
#[derive(Clone, Copy, Debug)]
pub struct Extras {
    /// A Viewpoint that frames every particle, looking down -z.
    pub viewpoint: bool,
    /// A key and a fill DirectionalLight, and the headlight off.
    pub lights: bool,
}

/// Writes particles as they come; [`ParticleWriter::finish`] adds the framing.
pub struct ParticleWriter<W: Write> {
    out: W,
    plain: bool,
    /// Particles are `GasParticle`s with their profiles.
    profiles: bool,
    /// `--radius`: instances leave the radius to the PROTO's default.
    default_radius: Option<f64>,
    lo: DVec3,
    hi: DVec3,
    count: u64,
    buf: ryu::Buffer,
    /// `k / 255` for k in 0..=255, as written: 0-255 colours are common and costly to format.
    quotients: Vec<String>,
}

impl<W: Write> ParticleWriter<W> {
    /// Writes the file header (and the PROTO unless `plain`). `source` names the input;
    /// `profiles`: the particles carry density profiles, written as `GasParticle`s (not with
    /// `plain`, whose ordinary nodes cannot carry them: an error).
    pub fn new(
        mut out: W,
        source: &str,
        plain: bool,
        profiles: bool,
        default_radius: Option<f64>,
    ) -> io::Result<Self> {
        if plain && profiles {
            return Err(io::Error::other(
                "density profiles need the PROTO form: ordinary nodes cannot carry them (leave out --plain)",
            ));
        }
        writeln!(out, "#VRML V2.0 utf8")?;
        // At most 200 characters (truncating bytes could split a character and panic).
        let one_line: String = source
            .chars()
            .map(|c| if c == '\n' || c == '\r' { ' ' } else { c })
            .take(200)
            .collect();
        writeln!(
            out,
            "# Particles from {one_line}, written by gtsphere {}",
            env!("CARGO_PKG_VERSION")
        )?;
        if !plain {
            out.write_all(proto(default_radius.unwrap_or(1.0), profiles).as_bytes())?;
        }
        Ok(ParticleWriter {
            out,
            plain,
            profiles,
            default_radius,
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
            count: 0,
            buf: ryu::Buffer::new(),
            quotients: (0..=255u32)
                .map(|k| number::format(&mut ryu::Buffer::new(), f64::from(k) / 255.0).to_string())
                .collect(),
        })
    }

    fn num(&mut self, n: Num<'_>) -> io::Result<()> {
        match n.text {
            Some(t) => self.out.write_all(t),
            None => self.f64(n.value),
        }
    }

    fn f64(&mut self, v: f64) -> io::Result<()> {
        let k = (v * 255.0).round();
        // Not for -0 (k = -0 passes the other tests), whose sign the rule keeps.
        if (0.0..=255.0).contains(&k) && k.is_sign_positive() && k / 255.0 == v {
            return self.out.write_all(self.quotients[k as usize].as_bytes());
        }
        self.out
            .write_all(number::format(&mut self.buf, v).as_bytes())
    }

    fn nums(&mut self, v: [Num<'_>; 3]) -> io::Result<()> {
        self.num(v[0])?;
        self.out.write_all(b" ")?;
        self.num(v[1])?;
        self.out.write_all(b" ")?;
        self.num(v[2])
    }

    fn vec3(&mut self, v: [f64; 3]) -> io::Result<()> {
        self.nums(v.map(|value| Num { value, text: None }))
    }

    /// Writes one particle.
    pub fn particle(&mut self, p: &Particle<'_>) -> io::Result<()> {
        let c = DVec3::new(
            p.position[0].value,
            p.position[1].value,
            p.position[2].value,
        );
        let r = p.radius.value;
        self.lo = self.lo.min(c - r);
        self.hi = self.hi.max(c + r);
        self.count += 1;
        if self.plain {
            return self.plain_particle(p);
        }
        self.out.write_all(if self.profiles {
            b"GasParticle { position "
        } else {
            b"Particle { position "
        })?;
        self.nums(p.position)?;
        if self.default_radius.is_none() {
            self.out.write_all(b" radius ")?;
            self.num(p.radius)?;
        }
        self.material(p, [&b" color "[..], b" emission "])?;
        match p.profile {
            None | Some(Profile::Constant) => {}
            Some(Profile::Gaussian { width }) => {
                self.out.write_all(b" profile \"gaussian\" width ")?;
                self.f64(width)?;
            }
            Some(other) => write!(self.out, " profile \"{}\"", other.name())?,
        }
        self.out.write_all(b" }\n")
    }

    /// The colour, emission and transparency fields that differ from the defaults, named
    /// `names` (colour, emission).
    fn material(&mut self, p: &Particle<'_>, names: [&[u8]; 2]) -> io::Result<()> {
        if let Some(c) = p.color {
            self.out.write_all(names[0])?;
            self.nums(c)?;
        }
        if let Some(e) = p.emission.filter(|e| e.iter().any(|n| n.value != 0.0)) {
            self.out.write_all(names[1])?;
            self.nums(e)?;
        }
        if let Some(t) = p.transparency.filter(|t| *t != 0.0) {
            self.out.write_all(b" transparency ")?;
            self.f64(t)?;
        }
        Ok(())
    }

    fn plain_particle(&mut self, p: &Particle<'_>) -> io::Result<()> {
        self.out.write_all(b"Transform { translation ")?;
        self.nums(p.position)?;
        self.out
            .write_all(b" children Shape { appearance Appearance { material Material {")?;
        self.material(p, [&b" diffuseColor "[..], b" emissiveColor "])?;
        self.out.write_all(b" } } geometry Sphere { radius ")?;
        self.num(p.radius)?;
        self.out.write_all(b" } } }\n")
    }

    /// How many particles were written.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The bounds of every sphere written, if any.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        (self.count > 0).then_some((self.lo, self.hi))
    }

    /// Position and field of view of a camera looking down -z that sees every sphere whole,
    /// or `None` when there are none or when that camera would stand beyond the range of f64
    /// (particles near +-1e308: the half-diagonal and the distance are computed without
    /// overflow where they fit, and refused where they do not).
    pub fn framing(&self) -> Option<(DVec3, f64)> {
        // Streamed: the ball is the one around the bounds (half their diagonal, computed
        // without overflow where it fits), as the spheres are gone by the end.
        let (lo, hi) = self.bounds()?;
        let centre = 0.5 * lo + 0.5 * hi;
        let half = 0.5 * hi - 0.5 * lo;
        let m = half.abs().max_element();
        let radius = if m > 0.0 {
            m * (half / m).length()
        } else {
            0.0
        };
        let position = crate::scene::framing_position(centre, radius)?;
        Some((position, crate::scene::FRAMING_FOV))
    }

    /// Adds the framing Viewpoint and lights, and returns the writer.
    pub fn finish(mut self, extras: Extras) -> io::Result<W> {
        writeln!(self.out, "# {} particles", self.count)?;
        if extras.lights {
            // A key light from the upper left, on the camera's side, casting shadows down
            // and to the right, and a weaker fill from the camera so that shadows are not
            // black. Fixed in the world, so other browsers show the same.
            self.out.write_all(
                b"NavigationInfo { headlight FALSE }\n\
                  DirectionalLight { direction 1 -1 -1 intensity 0.8 ambientIntensity 0.3 }\n\
                  DirectionalLight { direction 0 0 -1 intensity 0.3 }\n",
            )?;
        }
        if let (true, Some((position, fov))) = (extras.viewpoint, self.framing()) {
            self.out.write_all(b"Viewpoint { position ")?;
            self.vec3(position.to_array())?;
            self.out.write_all(b" fieldOfView ")?;
            self.f64(fov)?;
            self.out.write_all(b" description \"all particles\" }\n")?;
        }
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_non_ascii_source_names_are_cut_at_a_character() {
        // Byte 200 falls inside an "\u{e9}" (2 bytes each, after 3 one-byte characters).
        let name = "ab\n".to_string() + &"\u{e9}".repeat(300);
        let w = ParticleWriter::new(Vec::new(), &name, true, false, None).unwrap();
        let extras = Extras {
            viewpoint: false,
            lights: false,
        };
        let out = String::from_utf8(w.finish(extras).unwrap()).unwrap();
        let want = format!(
            "# Particles from ab {}, written by gtsphere {}",
            "\u{e9}".repeat(197),
            env!("CARGO_PKG_VERSION")
        );
        assert_eq!(out.lines().nth(1).unwrap(), want);
    }
}

//! Radial density profiles of gas spheres (docs/model.md section 6): which profile a material
//! has. Their mathematics (the density, its integral, the optical depth of chords) is in
//! `render::profile`.

/// A radial density profile `f(u)`, `u = |x - c| / r` (docs/model.md section 6).
///
/// | name | `f(u)` on `[0, 1]` | `I_f` = integral of `f` over `[0, 1]` |
/// |---|---|---|
/// | `constant` | 1 | 1 |
/// | `linear` | `1 - u` | 1/2 |
/// | `quadratic` | `1 - u^2` | 2/3 |
/// | `gaussian` (width `s` in (0, 1], default 1/3) | `exp(-u^2 / (2 s^2))` | `s sqrt(pi/2) erf(1 / (s sqrt 2))` |
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Profile {
    /// docs/model.md section 3's gas, the default.
    #[default]
    Constant,
    /// `f(u) = 1 - u`.
    Linear,
    /// `f(u) = 1 - u^2`.
    Quadratic,
    /// Cut at `u = 1`; `width` is `s` in units of the radius, in (0, 1] ([`Profile::parse`]
    /// checks it; the integrals assume it).
    Gaussian {
        /// The width `s`, in units of the radius, in (0, 1].
        width: f64,
    },
}

/// The width of the gaussian profile when none is given.
pub const DEFAULT_WIDTH: f64 = 1.0 / 3.0;

/// Why a profile name or width was refused by [`Profile::parse`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProfileError {
    /// A name other than `constant`, `linear`, `quadratic` and `gaussian`.
    #[error("unknown density profile `{0}` (expected constant, linear, quadratic or gaussian)")]
    UnknownName(String),
    /// A gaussian width outside (0, 1], or NaN.
    #[error("gaussian width {0} is outside (0, 1] (in units of the sphere's radius)")]
    Width(f64),
    /// A width given to a profile (named here) that takes none.
    #[error("the {0} profile takes no width (only gaussian has one)")]
    NoWidth(&'static str),
}

impl Profile {
    /// The profile called `name` (`constant`, `linear`, `quadratic`, `gaussian`, exactly),
    /// with `width` for the gaussian ([`DEFAULT_WIDTH`] when `None`). A width outside (0, 1]
    /// (NaN included), or a width given to another profile, is an error.
    pub fn parse(name: &str, width: Option<f64>) -> Result<Profile, ProfileError> {
        let p = match name {
            "constant" => Profile::Constant,
            "linear" => Profile::Linear,
            "quadratic" => Profile::Quadratic,
            "gaussian" => {
                let width = width.unwrap_or(DEFAULT_WIDTH);
                // Also refuses NaN.
                if !(width > 0.0 && width <= 1.0) {
                    return Err(ProfileError::Width(width));
                }
                return Ok(Profile::Gaussian { width });
            }
            _ => return Err(ProfileError::UnknownName(name.to_string())),
        };
        match width {
            Some(_) => Err(ProfileError::NoWidth(p.name())),
            None => Ok(p),
        }
    }

    /// [`Profile::parse`] for a profile read from a scene or a table, where a width may be
    /// given beside any name (a `GasParticle`'s `width` field, a `width` column that fills
    /// every row): the width counts for the gaussian only. Also returns the width that did
    /// not count (given to another profile), for the caller to warn about or not.
    pub(crate) fn parse_beside(
        name: &str,
        width: Option<f64>,
    ) -> Result<(Profile, Option<f64>), ProfileError> {
        if name == "gaussian" {
            return Profile::parse(name, width).map(|p| (p, None));
        }
        Profile::parse(name, None).map(|p| (p, width))
    }

    /// The name [`Profile::parse`] reads.
    pub fn name(&self) -> &'static str {
        match self {
            Profile::Constant => "constant",
            Profile::Linear => "linear",
            Profile::Quadratic => "quadratic",
            Profile::Gaussian { .. } => "gaussian",
        }
    }

    /// The profile's bits (which profile, and the gaussian's width): materials are equal
    /// when their keys are.
    pub fn key(&self) -> [u64; 2] {
        match *self {
            Profile::Constant => [0, 0],
            Profile::Linear => [1, 0],
            Profile::Quadratic => [2, 0],
            Profile::Gaussian { width } => [3, width.to_bits()],
        }
    }
}

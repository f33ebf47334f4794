//! The ambient occlusion options of `gtsphere render --integrator ao`: their validation into
//! [`AoSettings`], and the sentence that says which AO a render computes.

use clap::{Args, ValueEnum};

use gtsphere::render::ao::methods::{voxel, AoMethod, MAX_DIRECTIONS, MAX_SAMPLES};
use gtsphere::render::ao::{AoSettings, Weighting};
use gtsphere::scene::SurfaceCounts;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AoMethodArg {
    /// The exact unoccluded fraction (the default).
    Exact,
    /// Monte Carlo, as OSPRay, Tachyon and Blender: --ao-samples cosine-weighted rays per
    /// point, seeded per pixel; the error AOV holds its standard error.
    Mc,
    /// Fixed directions over the whole sphere, as ChimeraX's multishadow lighting:
    /// --ao-directions of them (Bauer's spiral), those above the horizon traced.
    Directions,
    /// Each sphere's form factor summed and clamped at 1, as shaders' analytic sphere
    /// occlusion: exact for one occluder, overlaps counted twice.
    Sum,
    /// MegaMol's MDAO: three 50-degree cones traced through a 128-voxel density grid of the
    /// spheres (the sphere a point is on occludes it too).
    Voxel,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum WeightingArg {
    /// By the cosine to the normal: the light a diffuse surface gets from a uniform sky (the
    /// default).
    Cosine,
    /// Uniformly: the fraction of the hemisphere's solid angle.
    Uniform,
}

impl WeightingArg {
    pub fn weighting(self) -> Weighting {
        match self {
            WeightingArg::Cosine => Weighting::Cosine,
            WeightingArg::Uniform => Weighting::Uniform,
        }
    }
}

/// The distance `--ao-reach` gives (infinite when not given), refused unless positive.
pub fn reach_of(ao_reach: Option<f64>) -> Result<f64, String> {
    match ao_reach {
        Some(d) if d.is_nan() || d <= 0.0 => {
            Err(format!("--ao-reach must be a positive distance (got {d})"))
        }
        Some(d) => Ok(d),
        None => Ok(f64::INFINITY),
    }
}

/// The options of `--integrator ao`.
#[derive(Debug, Args)]
pub struct AoArgs {
    /// `--integrator ao`: the distance within which an occluder occludes (world units;
    /// default: any distance, at a cost per pixel that grows with the scene).
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub ao_reach: Option<f64>,
    /// `--integrator ao`: how directions of the hemisphere are weighted (default: cosine).
    #[arg(long, value_enum)]
    pub ao_weighting: Option<WeightingArg>,
    /// `--integrator ao`: the unoccluded fraction times each surface's diffuseColor, instead
    /// of on white.
    #[arg(long)]
    pub ao_colours: bool,
    /// `--integrator ao`: how the unoccluded fraction is computed. Every method but exact is
    /// an approximation some tool uses, named to be compared with exact (`gtsphere compare`;
    /// docs/ao-methods.md). Default: exact.
    #[arg(long, value_enum, value_name = "METHOD")]
    pub ao_method: Option<AoMethodArg>,
    /// `--ao-method mc`: rays per shading point (1 to 1048576; default 16).
    #[arg(long, value_name = "N")]
    pub ao_samples: Option<u32>,
    /// `--ao-method directions`: directions over the whole sphere (1 to 65536; default 64,
    /// ChimeraX's in its soft and full lighting).
    #[arg(long, value_name = "K")]
    pub ao_directions: Option<u32>,
}

impl AoArgs {
    /// The options given, by name, with the method each is for.
    fn given(&self) -> Vec<&'static str> {
        [
            (self.ao_reach.is_some(), "--ao-reach"),
            (self.ao_weighting.is_some(), "--ao-weighting"),
            (self.ao_colours, "--ao-colours"),
            (self.ao_method.is_some(), "--ao-method"),
            (self.ao_samples.is_some(), "--ao-samples"),
            (self.ao_directions.is_some(), "--ao-directions"),
        ]
        .into_iter()
        .filter_map(|(on, name)| on.then_some(name))
        .collect()
    }

    /// Refuses AO options on a render that is not `--integrator ao`; with the `ao` channel
    /// (`aov`), its reach and weighting are used.
    pub fn check_unused(&self, aov: bool) -> Result<(), String> {
        let given: Vec<&str> = self
            .given()
            .into_iter()
            .filter(|&o| !(aov && (o == "--ao-reach" || o == "--ao-weighting")))
            .collect();
        match given.as_slice() {
            [] => Ok(()),
            [one] => Err(format!("{one} is only for --integrator ao")),
            many => Err(format!("{} are only for --integrator ao", many.join(", "))),
        }
    }

    /// The settings of `--integrator ao`.
    pub fn settings(&self) -> Result<AoSettings, String> {
        let reach = reach_of(self.ao_reach)?;
        let method = self.ao_method.unwrap_or(AoMethodArg::Exact);
        if self.ao_samples.is_some() && method != AoMethodArg::Mc {
            return Err("--ao-samples is only for --ao-method mc".into());
        }
        if self.ao_directions.is_some() && method != AoMethodArg::Directions {
            return Err("--ao-directions is only for --ao-method directions".into());
        }
        let method = match method {
            AoMethodArg::Exact => AoMethod::Exact,
            AoMethodArg::Mc => {
                let samples = self.ao_samples.unwrap_or(16);
                if !(1..=MAX_SAMPLES).contains(&samples) {
                    return Err(format!(
                        "--ao-samples must be between 1 and {MAX_SAMPLES} (got {samples})"
                    ));
                }
                AoMethod::Mc { samples }
            }
            AoMethodArg::Directions => {
                let count = self.ao_directions.unwrap_or(64);
                if !(1..=MAX_DIRECTIONS).contains(&count) {
                    return Err(format!(
                        "--ao-directions must be between 1 and {MAX_DIRECTIONS} (got {count})"
                    ));
                }
                AoMethod::Directions { count }
            }
            AoMethodArg::Sum => AoMethod::Sum,
            AoMethodArg::Voxel => AoMethod::VOXEL,
        };
        Ok(AoSettings {
            reach,
            weighting: self
                .ao_weighting
                .map_or(Weighting::Cosine, WeightingArg::weighting),
            colours: self.ao_colours,
            method,
        })
    }
}

/// From how many faces exact AO with no reach is worth a note on its cost.
const MANY_FACES: usize = 1000;
/// The faces a cylinder or a cone counts as: its polyhedra's faces that face a point, at
/// their fewest sides (`bracket` in the library).
const ROUND_FACES: usize = 6;

/// A note on the cost of exact AO with no reach among the scene's triangles, boxes,
/// cylinders and cones (`counts`), when there are many: every one visible from a point enters
/// its union, whose work grows faster than their number (docs/benchmarks.md has the
/// measurements).
pub fn cost_note(ao: &AoSettings, counts: &SurfaceCounts) -> Option<String> {
    let rounds = counts.cylinders + counts.cones;
    let faces = counts.triangles + counts.boxes + ROUND_FACES * rounds;
    (ao.reach.is_infinite() && faces >= MANY_FACES).then(|| {
        format!(
            "note: with no --ao-reach, exact AO takes every surface other than spheres that a \
             point sees ({} in the scene) into its union, at a cost per pixel that grows \
             faster than their number: seconds per pixel among tens of thousands of \
             triangles, or thousands of cylinders and cones. --ao-reach D bounds it to those \
             within D",
            counts.triangles + counts.boxes + rounds
        )
    })
}

/// From how many gas spheres exact AO with no reach is worth a note on its cost.
const MANY_GAS: usize = 200;

/// A note on the cost of exact AO with no reach through `gas` gas spheres, when there are
/// many: each point integrates the gas's transmittance over the directions between the
/// circles of every gas sphere it sees, and each evaluation sums the depths of them all, so
/// the work per pixel grows about as their number squared (tens of milliseconds among 40 on
/// `samples/gas.wrl`, about 2 s among 250 in a random cloud: docs/benchmarks.md).
pub fn gas_note(ao: &AoSettings, gas: usize) -> Option<String> {
    (ao.reach.is_infinite() && gas >= MANY_GAS).then(|| {
        format!(
            "note: with no --ao-reach, exact AO through gas integrates over every gas sphere a \
             point sees ({gas} in the scene), at a cost per pixel that grows about as their \
             number squared: tens of milliseconds among 40, about 2 s among 250. \
             --ao-reach D bounds it to those within D"
        )
    })
}

/// What a render with `ao` computes, in a sentence; `grid` is the voxel method's.
pub fn describe(ao: &AoSettings, grid: Option<&voxel::Grid>) -> String {
    let method = match ao.method {
        AoMethod::Exact => "exact".to_string(),
        AoMethod::Mc { samples } => {
            format!("Monte Carlo, {samples} rays per point (an approximation)")
        }
        AoMethod::Directions { count } => {
            format!("from {count} fixed directions (an approximation)")
        }
        AoMethod::Sum => "the spheres' form factors summed (an approximation)".to_string(),
        AoMethod::Voxel(_) => match grid {
            Some(g) => {
                let [x, y, z] = g.dims();
                format!(
                    "voxel cone tracing in a {x}x{y}x{z} grid of {:.1} MB (an approximation)",
                    g.bytes() as f64 / 1e6
                )
            }
            None => "voxel cone tracing (an approximation)".to_string(),
        },
    };
    format!(
        "ambient occlusion, {method}, {} weighting, reach {}{}",
        match ao.weighting {
            Weighting::Cosine => "cosine",
            Weighting::Uniform => "uniform",
        },
        if ao.reach.is_finite() {
            format!("{}", ao.reach)
        } else {
            "unlimited".into()
        },
        if ao.colours {
            ", on diffuse colours"
        } else {
            ""
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cost_note_comes_with_no_reach_among_many_surfaces_only() {
        let mut ao = AoSettings::default();
        assert!(ao.reach.is_infinite());
        let counts = |triangles, cylinders| SurfaceCounts {
            triangles,
            cylinders,
            ..SurfaceCounts::default()
        };
        let note = cost_note(&ao, &counts(MANY_FACES, 0)).expect("a note");
        assert!(note.contains("--ao-reach") && note.contains(&MANY_FACES.to_string()));
        assert_eq!(cost_note(&ao, &counts(MANY_FACES - 1, 0)), None);
        // A cylinder counts as several faces.
        assert!(cost_note(&ao, &counts(0, MANY_FACES / ROUND_FACES + 1)).is_some());
        assert_eq!(
            cost_note(&ao, &counts(0, MANY_FACES / ROUND_FACES - 1)),
            None
        );
        ao.reach = 2.0;
        assert_eq!(cost_note(&ao, &counts(10 * MANY_FACES, 0)), None);
    }

    #[test]
    fn the_gas_note_comes_with_no_reach_among_many_gas_spheres_only() {
        let mut ao = AoSettings::default();
        let note = gas_note(&ao, MANY_GAS).expect("a note");
        assert!(note.contains("--ao-reach") && note.contains(&MANY_GAS.to_string()));
        assert_eq!(gas_note(&ao, MANY_GAS - 1), None);
        ao.reach = 2.0;
        assert_eq!(gas_note(&ao, 10 * MANY_GAS), None);
    }
}

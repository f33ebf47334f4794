//! The integrators ray by ray against independent answers: closed forms, and the brute-force
//! gas references written here from the model alone (docs/model.md sections 3 and 6).

mod gas_mc; // the Monte Carlo integrator: standard errors honest, agrees with exact
pub(crate) mod gas_reference; // the brute-force gas reference the gas tests share (its checks: gas_scatter)
mod gas_scatter; // exact single scattering against the brute-force reference, and the reference's own checks
mod gas_truncation; // exact: truncation bounds and error estimates against the reference
mod hard_cases; // numerical hard cases: tiny, huge, far, tangent, coincident
mod profiled_gas; // gas with density profiles: closed forms, tolerance, error estimates, mc, against the reference
pub(crate) mod profiled_reference; // the brute-force reference for profiled gas (numerical density integrals) and its own checks
mod render_gas; // gas emission and absorption against closed forms
mod shadow_edge; // a shadow's edge on a lit sphere where the blocker's shadow cylinder puts it

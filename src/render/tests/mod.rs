//! The shared pieces of rendering against brute force: the lights' grids and the shadow
//! query against testing every sphere, profiles' optical depth against quadrature, the
//! surface BVH against testing every primitive.

mod gas_particle; // prepare gives GasParticle gas its profile and centre density
mod light_grid; // the lights' grids: candidates hold every sphere a band meets, and prune
mod profile_chords; // density profiles' closed-form optical depth against independent quadrature
mod shadow_query; // the shadow-volume query against testing every sphere
mod surface_bvh; // closest and any hit over mixed primitives against testing every one

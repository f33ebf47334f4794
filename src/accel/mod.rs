//! Acceleration structures: the sphere BVH (f32 boxes, f64 tests).

pub mod bvh;

pub use bvh::{Ball, Hit, Packed, PacketStack, Prim, SphereBvh, PACKET};

#[cfg(test)]
mod tests;

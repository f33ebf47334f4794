//! The reader's and writers' internals: PROTO instances lowered by a compiled sphere template
//! and sphere nodes read whole against the plain path, the schema's support tables as
//! docs/vrml.md shows them, and the writers' one number format.

mod number_format; // both VRML writers format numbers alike, and they read back bit for bit
mod proto_template; // PROTO instances lowered by a compiled sphere template equal the body's replay
mod vrml_support; // docs/vrml.md is made of the schema's support tables, and they say what the reader does
mod whole_sphere_nodes; // plain sphere nodes read whole from the text equal their events

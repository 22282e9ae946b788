//! Model loaders. Every loader ends in the same [`crate::ModelBuilder`]; nothing about a file
//! format reaches the algorithms.

pub mod bundled;
pub mod urdf;

pub use bundled::{bundled_model, bundled_names};
pub use urdf::{load_urdf_file, load_urdf_str};

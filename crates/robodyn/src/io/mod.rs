//! Model loaders. Every loader ends in the same [`crate::ModelBuilder`]; nothing about a file
//! format reaches the algorithms.

pub mod bundled;
pub mod dh;
pub mod mesh;
pub mod mjcf;
mod schema;
pub mod snapshot;
pub mod urdf;
mod urdf_schema;
mod xml;

pub use xml::MAX_NESTING;

pub use bundled::{bundled_model, bundled_names, bundled_urdf};
pub use dh::{
    build_dh, load_dh_document, load_dh_file, load_dh_str, DhConvention, DhJoint, DhRow, DhTable,
};
pub use mjcf::{load_mjcf_file, load_mjcf_str};
pub use snapshot::{model_from_bytes, model_to_bytes};
pub use urdf::{load_urdf_file, load_urdf_str};

/// How a model file is turned into a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoadOptions {
    /// Put a free joint named `root_joint` between the world and the root link.
    pub floating_base: bool,
    /// Reject inertias that are not positive semi-definite (otherwise: a warning on the model).
    pub check_inertia: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            floating_base: false,
            check_inertia: true,
        }
    }
}

impl LoadOptions {
    /// The defaults, with or without a floating base.
    pub fn floating(floating_base: bool) -> Self {
        LoadOptions {
            floating_base,
            ..LoadOptions::default()
        }
    }
}

/// The text of a model file; a missing file is [`Error::FileNotFound`].
pub(crate) fn read_model_file(path: &std::path::Path) -> crate::Result<String> {
    std::fs::read_to_string(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => crate::Error::FileNotFound {
            path: path.display().to_string(),
        },
        _ => crate::Error::model(
            path.display().to_string(),
            format!("cannot read the file: {e}"),
        ),
    })
}

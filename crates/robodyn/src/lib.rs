//! robodyn: rigid-body dynamics for robots.
//!
//! The core is pure Rust: spatial (Plücker) algebra, joints, a [`Model`] built from URDF by the
//! loaders in [`io`], a preallocated [`Data`] workspace, and one free function per algorithm in
//! [`algo`] (forward kinematics, Jacobians, RNEA, CRBA, ABA, energies). Algorithms never allocate
//! after [`Data::new`] and never panic on user input: every entry point validates its arguments and
//! returns [`Error`].
//!
//! Conventions: bodies are numbered so that `parent[i] < i`, body 0 is the world; flattened
//! 6-vectors at the public boundary are `[linear; angular]`; units are SI.

#![warn(missing_docs)]

pub mod algo;
pub mod collision;
pub mod constraint;
pub mod data;
mod dispatch;
pub mod error;
pub mod integrate;
pub mod io;
pub mod joint;
pub mod model;
pub mod soft;
pub mod spatial;
pub mod visual;

pub use data::Data;
pub use error::{Error, Result};
pub use joint::Joint;
pub use model::{Actuator, Frame, JointProperties, Keyframe, Mimic, Model, ModelBuilder, NewBody};

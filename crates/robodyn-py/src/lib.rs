//! PyO3 glue for robodyn: argument conversion, batching over all cores with the GIL released, and
//! errors turned into `ValueError` / `FileNotFoundError`. No physics lives here.

use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use robodyn::Error;

/// The extension's allocator: mimalloc, whose blocks of a few KiB to a few hundred KiB (a large
/// robot's Jacobian, mass matrix or derivatives) come from per-thread free lists, where the C
/// library's `malloc` searches sorted bins (`results.rs`).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod args;
mod dynamics;
mod kinematics;
mod loaders;
mod model;
mod properties;
mod results;
mod simulation;
mod visuals;

use loaders::*;
use model::PyModel;

pyo3::create_exception!(
    robodyn,
    SimulationError,
    PyValueError,
    "A simulation stopped: it diverged (the message says when, which quantity and joint, and \
     a step that keeps it stable), or its controller or wrenches gave something unusable."
);

/// A core error as the Python exception the API promises.
pub(crate) fn to_py_err(error: Error) -> PyErr {
    match error {
        Error::FileNotFound { .. } => PyFileNotFoundError::new_err(error.to_string()),
        Error::Simulation { .. } | Error::Diverged { .. } => {
            SimulationError::new_err(error.to_string())
        }
        _ => PyValueError::new_err(error.to_string()),
    }
}

#[pymodule]
fn _core(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<PyModel>()?;
    module.add("SimulationError", module.py().get_type::<SimulationError>())?;
    module.add_function(wrap_pyfunction!(load_urdf, module)?)?;
    module.add_function(wrap_pyfunction!(load_urdf_string, module)?)?;
    module.add_function(wrap_pyfunction!(load_bundled, module)?)?;
    module.add_function(wrap_pyfunction!(load_dh, module)?)?;
    module.add_function(wrap_pyfunction!(load_mjcf, module)?)?;
    module.add_function(wrap_pyfunction!(load_mjcf_string, module)?)?;
    module.add_function(wrap_pyfunction!(load_dh_dict, module)?)?;
    module.add_function(wrap_pyfunction!(bundled_names, module)?)?;
    module.add_function(wrap_pyfunction!(bundled_urdf, module)?)?;
    module.add_function(wrap_pyfunction!(model_from_bytes, module)?)?;
    module.add_function(wrap_pyfunction!(simulation::simulate, module)?)?;
    module.add_function(wrap_pyfunction!(simulation::step, module)?)?;
    module.add_function(wrap_pyfunction!(visuals::read_mesh_file, module)?)?;
    module.add_function(wrap_pyfunction!(
        properties::check_physical_parameters,
        module
    )?)?;
    Ok(())
}

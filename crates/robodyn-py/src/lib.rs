//! PyO3 glue for robodyn: argument conversion, batching over all cores with the GIL released, and
//! errors turned into `ValueError` / `FileNotFoundError`. No physics lives here.

use pyo3::prelude::*;

/// The extension's allocator: mimalloc, whose blocks of a few KiB to a few hundred KiB (a large
/// robot's Jacobian, mass matrix or derivatives) come from per-thread free lists, where the C
/// library's `malloc` searches sorted bins (`results.rs`).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod actuators;
mod args;
mod constrained;
mod constraints;
mod contact_dynamics;
mod dynamics;
mod errors;
mod keyframes;
mod kinematics;
mod loaders;
mod model;
mod properties;
mod results;
mod scene;
mod simulation;
mod tendons;
mod visuals;

use loaders::*;
use model::PyModel;

pub(crate) use errors::to_py_err;
use errors::SimulationError;

#[pymodule]
fn _core(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<PyModel>()?;
    module.add_class::<constraints::PyPointAnchor>()?;
    module.add_class::<constraints::PyFrameAnchor>()?;
    module.add_class::<constraints::PyJointCoupling>()?;
    module.add_class::<constraints::PyDistance>()?;
    module.add_class::<keyframes::PyKeyframe>()?;
    module.add_class::<scene::PyOptions>()?;
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
    module.add_function(wrap_pyfunction!(simulation::simulate_scene, module)?)?;
    module.add_function(wrap_pyfunction!(simulation::step_scene, module)?)?;
    module.add_function(wrap_pyfunction!(visuals::read_mesh_file, module)?)?;
    module.add_function(wrap_pyfunction!(
        properties::check_physical_parameters,
        module
    )?)?;
    Ok(())
}

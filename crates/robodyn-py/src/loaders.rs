//! Loaders: URDF, MJCF and DH tables from files, strings and dicts, the bundled models, and a
//! model's own bytes (pickling).

use crate::args::named;
use crate::model::*;
use crate::to_py_err;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use robodyn::io::LoadOptions;

/// Loads a URDF file. `floating_base` adds a free joint "root_joint" above the root link;
/// `check_inertia=False` turns a non-positive-semi-definite inertia from an error into a warning.
#[pyfunction]
#[pyo3(signature = (path, floating_base=false, check_inertia=true))]
pub(crate) fn load_urdf(
    #[pyo3(from_py_with = named::path)] path: std::path::PathBuf,
    #[pyo3(from_py_with = named::floating_base)] floating_base: bool,
    #[pyo3(from_py_with = named::check_inertia)] check_inertia: bool,
) -> PyResult<PyModel> {
    let options = LoadOptions {
        floating_base,
        check_inertia,
    };
    robodyn::io::load_urdf_file(&path, options)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Loads a URDF document from a string; `source` names it in error messages.
#[pyfunction]
#[pyo3(signature = (text, floating_base=false, check_inertia=true, source="<string>".to_string()), text_signature = "(text, floating_base=False, check_inertia=True, source='<string>')")]
pub(crate) fn load_urdf_string(
    #[pyo3(from_py_with = named::text)] text: String,
    #[pyo3(from_py_with = named::floating_base)] floating_base: bool,
    #[pyo3(from_py_with = named::check_inertia)] check_inertia: bool,
    #[pyo3(from_py_with = named::source)] source: String,
) -> PyResult<PyModel> {
    let options = LoadOptions {
        floating_base,
        check_inertia,
    };
    robodyn::io::load_urdf_str(&text, &source, options)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Loads an MJCF (MuJoCo XML) file.
#[pyfunction]
pub(crate) fn load_mjcf(
    #[pyo3(from_py_with = named::path)] path: std::path::PathBuf,
) -> PyResult<PyModel> {
    robodyn::io::load_mjcf_file(&path)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Loads an MJCF document from a string; `source` names it in error messages.
#[pyfunction]
#[pyo3(signature = (text, source="<string>".to_string()), text_signature = "(text, source='<string>')")]
pub(crate) fn load_mjcf_string(
    #[pyo3(from_py_with = named::text)] text: String,
    #[pyo3(from_py_with = named::source)] source: String,
) -> PyResult<PyModel> {
    robodyn::io::load_mjcf_str(&text, &source)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Loads a DH table file (TOML).
#[pyfunction]
pub(crate) fn load_dh(path: std::path::PathBuf) -> PyResult<PyModel> {
    robodyn::io::load_dh_file(&path)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// Builds a model from a DH table given as a dict with the keys of the TOML format.
#[pyfunction]
#[pyo3(signature = (document, source="from_dh"))]
pub(crate) fn load_dh_dict(document: &Bound<PyDict>, source: &str) -> PyResult<PyModel> {
    let toml::Value::Table(table) = toml_value(document.as_any(), "table")? else {
        return Err(PyValueError::new_err(
            "argument 'document': expected a dict",
        ));
    };
    robodyn::io::load_dh_document(&table, source)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// A Python value (dict, list, str, bool, int, float, NumPy array) as a TOML value.
pub(crate) fn toml_value(value: &Bound<PyAny>, key: &str) -> PyResult<toml::Value> {
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in dict.iter() {
            let k: String = k
                .extract()
                .map_err(|_| PyValueError::new_err(format!("'{key}': expected string keys")))?;
            let item = toml_value(&v, &k)?;
            table.insert(k, item);
        }
        return Ok(toml::Value::Table(table));
    }
    if let Ok(text) = value.extract::<String>() {
        return Ok(toml::Value::String(text));
    }
    if let Ok(flag) = value.extract::<bool>() {
        return Ok(toml::Value::Boolean(flag));
    }
    if let Ok(number) = value.extract::<f64>() {
        return Ok(toml::Value::Float(number));
    }
    if let Ok(items) = value.try_iter() {
        return items
            .map(|item| toml_value(&item?, key))
            .collect::<PyResult<Vec<_>>>()
            .map(toml::Value::Array);
    }
    Err(PyValueError::new_err(format!(
        "'{key}': expected a number, a string, a list or a dict, got {}",
        value.repr()?
    )))
}

/// A model bundled with robodyn, by name.
#[pyfunction]
#[pyo3(signature = (name, floating_base=false))]
pub(crate) fn load_bundled(name: &str, floating_base: bool) -> PyResult<PyModel> {
    robodyn::io::bundled_model(name, floating_base)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

/// The URDF text and gravity of a bundled model (for the symbolic layer, which reads URDF).
#[pyfunction]
pub(crate) fn bundled_urdf(name: &str) -> PyResult<(&'static str, [f64; 3])> {
    robodyn::io::bundled_urdf(name).map_err(to_py_err)
}

/// Names of the bundled models.
#[pyfunction]
pub(crate) fn bundled_names() -> Vec<&'static str> {
    robodyn::io::bundled_names()
}

/// A model from the bytes `Model.__reduce__` gives (pickle, `copy.deepcopy`, worker processes):
/// every field, edits made after loading included. Bytes of another robodyn model format, or
/// damaged ones, are a `ValueError` saying which.
#[pyfunction(name = "_model_from_bytes")]
pub(crate) fn model_from_bytes(data: &[u8]) -> PyResult<PyModel> {
    robodyn::io::model_from_bytes(data)
        .map(PyModel::wrap)
        .map_err(to_py_err)
}

#[pymethods]
impl PyModel {
    /// Pickling and copying: the model as bytes, and the function that reads them back.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let function = py.import("robodyn._core")?.getattr("_model_from_bytes")?;
        let bytes = PyBytes::new(py, &robodyn::io::model_to_bytes(&self.model));
        Ok((function, (bytes,)))
    }
}

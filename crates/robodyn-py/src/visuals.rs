//! What the robot looks like, for the viewer: the model's visuals as dicts, and MuJoCo's mesh
//! formats read by the same readers the mesh inertias use.

use crate::args::named;
use crate::model::PyModel;
use nalgebra::Matrix4;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::io::mesh::{read_mesh, TriangleMesh};
use robodyn::visual::{MeshSource, Shape, Texture, TextureImage};

/// A triangle mesh as NumPy arrays: vertices (n, 3) and faces (m, 3).
type MeshArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>);

/// A 4x4 matrix as a NumPy array.
pub(crate) fn matrix<'py>(py: Python<'py>, m: &Matrix4<f64>) -> PyResult<Bound<'py, PyAny>> {
    let rows: Vec<f64> = (0..16).map(|k| m[(k / 4, k % 4)]).collect();
    Ok(PyArray1::from_vec(py, rows).reshape([4, 4])?.into_any())
}

/// A shape's size in MJCF's convention: half-extents, radius, [radius, half-length]; a height
/// field's half-sides, top and base; none for a mesh.
pub(crate) fn shape_size(shape: &Shape) -> Vec<f64> {
    match shape {
        Shape::Box { half_extents } => half_extents.as_slice().to_vec(),
        Shape::Ellipsoid { radii } => radii.as_slice().to_vec(),
        Shape::Sphere { radius } => vec![*radius],
        Shape::Cylinder {
            radius,
            half_length,
        }
        | Shape::Capsule {
            radius,
            half_length,
        } => vec![*radius, *half_length],
        Shape::Plane { half_extents } => half_extents.to_vec(),
        Shape::Mesh { .. } => Vec::new(),
        Shape::HeightField { field } => {
            let [x, y] = field.half_extents;
            vec![x, y, field.top, field.base]
        }
    }
}

/// A triangle mesh as (vertices (n, 3), faces (m, 3)) arrays.
fn mesh_arrays<'py>(py: Python<'py>, mesh: &TriangleMesh) -> PyResult<MeshArrays<'py>> {
    let vertices: Vec<f64> = mesh.vertices.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
    let faces: Vec<i64> = mesh.faces.iter().flatten().map(|&i| i as i64).collect();
    Ok((
        PyArray1::from_vec(py, vertices).reshape([mesh.vertices.len(), 3])?,
        PyArray1::from_vec(py, faces).reshape([mesh.faces.len(), 3])?,
    ))
}

/// A texture as a dict: `name`, `kind` ("2d", "cube", "skybox"), `element`, and its image: `file`
/// (with `hflip`, `vflip`), or `builtin` (a dict: `pattern`, `rgb1`, `rgb2`, `mark`, `markrgb`,
/// `random`, `width`, `height`), or `undrawable` (why robodyn cannot draw it); the others None.
fn texture_dict<'py>(py: Python<'py>, texture: &Texture) -> PyResult<Bound<'py, PyDict>> {
    let item = PyDict::new(py);
    item.set_item("name", &texture.name)?;
    item.set_item("kind", texture.kind.as_str())?;
    item.set_item("element", &texture.element)?;
    item.set_item("file", py.None())?;
    item.set_item("builtin", py.None())?;
    item.set_item("undrawable", py.None())?;
    match &texture.image {
        TextureImage::File { path, hflip, vflip } => {
            item.set_item("file", path.display().to_string())?;
            item.set_item("hflip", *hflip)?;
            item.set_item("vflip", *vflip)?;
        }
        TextureImage::Builtin(builtin) => {
            let pattern = PyDict::new(py);
            pattern.set_item("pattern", &builtin.pattern)?;
            pattern.set_item("rgb1", builtin.rgb1.to_vec())?;
            pattern.set_item("rgb2", builtin.rgb2.to_vec())?;
            pattern.set_item("mark", &builtin.mark)?;
            pattern.set_item("markrgb", builtin.mark_rgb.to_vec())?;
            pattern.set_item("random", builtin.random)?;
            pattern.set_item("width", builtin.width)?;
            pattern.set_item("height", builtin.height)?;
            item.set_item("builtin", pattern)?;
        }
        TextureImage::Undrawable(why) => item.set_item("undrawable", why)?,
    }
    Ok(item)
}

#[pymethods]
impl PyModel {
    /// The scene's background texture (MJCF's first `<texture type="skybox">`) as a dict (see
    /// `visuals`' `texture`), or None.
    #[getter]
    fn skybox<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.model
            .skybox
            .as_ref()
            .map(|texture| texture_dict(py, texture))
            .transpose()
    }

    /// The robot's visual geometry (URDF `<visual>`s, MJCF geoms), one dict each: `name`,
    /// `body` (index into `["world"] + body_names`), `placement` (4x4 pose in the body),
    /// `kind` ("box", "sphere", "cylinder", "capsule", "ellipsoid", "plane", "mesh", "hfield"),
    /// `size` (MJCF's convention: half-extents, radius, [radius, half-length]; a height field's
    /// [x, y, top, base]), `rgba`, `group` (MJCF; MuJoCo shows 0–2), `element` (where it is
    /// written), for a height field its triangles as `mesh_vertices` and `mesh_faces` (in its
    /// frame: surface, walls and bottom), and for meshes `mesh_file` (or
    /// `mesh_vertices` and `mesh_faces` when written inline), `mesh_missing` (why the file was
    /// not found, else None) and `file_to_visual` (4x4, may scale); `texture`: None, or the
    /// texture its MJCF material lays on it, a dict with `name`, `kind` ("2d", "cube",
    /// "skybox"), `element`, `repeat` (`texrepeat`), `uniform` (`texuniform`) and its image:
    /// `file` (a PNG, with `hflip` and `vflip`), `builtin` (a dict: `pattern`, `rgb1`, `rgb2`,
    /// `mark`, `markrgb`, `random`, `width`, `height`) or `undrawable` (why it is not drawn).
    #[getter]
    fn visuals<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut visuals = Vec::with_capacity(self.model.visuals.len());
        for visual in &self.model.visuals {
            let item = PyDict::new(py);
            item.set_item("name", &visual.name)?;
            item.set_item("body", visual.body)?;
            item.set_item("placement", matrix(py, &visual.placement.to_homogeneous())?)?;
            item.set_item("kind", visual.shape.kind())?;
            item.set_item("size", shape_size(&visual.shape))?;
            item.set_item("rgba", visual.rgba.to_vec())?;
            item.set_item("group", visual.group)?;
            item.set_item("element", &visual.element)?;
            match &visual.texture {
                None => item.set_item("texture", py.None())?,
                Some(mapping) => {
                    let texture = texture_dict(py, &mapping.texture)?;
                    texture.set_item("repeat", mapping.repeat.to_vec())?;
                    texture.set_item("uniform", mapping.uniform)?;
                    item.set_item("texture", texture)?;
                }
            }
            if let Shape::HeightField { field } = &visual.shape {
                let (vertices, faces) = mesh_arrays(py, &field.triangles())?;
                item.set_item("mesh_vertices", vertices)?;
                item.set_item("mesh_faces", faces)?;
            }
            if let Shape::Mesh {
                source,
                file_to_visual,
                ..
            } = &visual.shape
            {
                item.set_item("file_to_visual", matrix(py, file_to_visual)?)?;
                let none = py.None();
                let (file, missing) = match source {
                    MeshSource::File(path) => (
                        path.display().to_string().into_pyobject(py)?.into_any(),
                        none.bind(py).clone(),
                    ),
                    MeshSource::Missing(why) => {
                        (none.bind(py).clone(), why.into_pyobject(py)?.into_any())
                    }
                    MeshSource::Inline(mesh) => {
                        let (vertices, faces) = mesh_arrays(py, mesh)?;
                        item.set_item("mesh_vertices", vertices)?;
                        item.set_item("mesh_faces", faces)?;
                        (none.bind(py).clone(), none.bind(py).clone())
                    }
                };
                item.set_item("mesh_file", file)?;
                item.set_item("mesh_missing", missing)?;
            }
            visuals.push(item);
        }
        Ok(visuals)
    }
}

/// Reads an STL (binary or ASCII), Wavefront OBJ or MuJoCo .msh file as (vertices (n, 3),
/// faces (m, 3)), triangulated as MuJoCo reads it.
#[pyfunction]
pub(crate) fn read_mesh_file<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = named::path)] path: std::path::PathBuf,
) -> PyResult<MeshArrays<'py>> {
    let bytes = std::fs::read(&path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => pyo3::exceptions::PyFileNotFoundError::new_err(format!(
            "mesh file '{}' not found",
            path.display()
        )),
        _ => PyValueError::new_err(format!("cannot read '{}': {e}", path.display())),
    })?;
    let extension = path
        .extension()
        .map_or_else(String::new, |e| e.to_string_lossy().to_lowercase());
    let file = read_mesh(&bytes, &extension)
        .map_err(|m| PyValueError::new_err(format!("{}: {m}", path.display())))?;
    mesh_arrays(py, &file.mesh)
}

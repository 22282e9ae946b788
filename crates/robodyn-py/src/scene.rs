//! What a scene file says of contacts and simulation: the collision geoms, the contact pairs and
//! exclusions, the joints' soft limits and friction, and the `<option>`s (`robodyn.Options`).

use crate::args::{read_sample, text, SampleShape};
use crate::errors::to_py_err;
use crate::model::PyModel;
use crate::visuals::{matrix, shape_size};
use nalgebra::{Matrix3, Vector3};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::model::{
    ConstraintSolver, FrictionCone, SimulationOptions, SolverParameters, DISABLE_FLAGS,
    ENABLE_FLAGS,
};

/// How the model file asks to be simulated (MJCF `<option>`; MuJoCo's defaults where it says
/// nothing), with MJCF's names. Read-only: what the file says. robodyn follows the `gravity`
/// flag (a model whose file disables it has no gravity) and the `equality` and `constraint`
/// flags (its equalities are inactive) when it reads the file; `robodyn.simulate` does not yet
/// read the rest.
#[pyclass(name = "Options", module = "robodyn", frozen)]
pub(crate) struct PyOptions {
    options: SimulationOptions,
}

fn solver_name(solver: ConstraintSolver) -> &'static str {
    match solver {
        ConstraintSolver::Pgs => "PGS",
        ConstraintSolver::Cg => "CG",
        ConstraintSolver::Newton => "Newton",
    }
}

#[pymethods]
impl PyOptions {
    /// The time step (s).
    #[getter]
    fn timestep(&self) -> f64 {
        self.options.timestep
    }

    /// "Euler", "RK4", "implicit", "implicitfast" or "discrete".
    #[getter]
    fn integrator(&self) -> &'static str {
        self.options.integrator.keyword()
    }

    /// "pyramidal" or "elliptic".
    #[getter]
    fn cone(&self) -> &'static str {
        match self.options.cone {
            FrictionCone::Pyramidal => "pyramidal",
            FrictionCone::Elliptic => "elliptic",
        }
    }

    /// "PGS", "CG" or "Newton".
    #[getter]
    fn solver(&self) -> &'static str {
        solver_name(self.options.solver)
    }

    /// The ratio of frictional to normal impedance (elliptic cones).
    #[getter]
    fn impratio(&self) -> f64 {
        self.options.impratio
    }

    /// The constraint solver's relative improvement at which it stops.
    #[getter]
    fn tolerance(&self) -> f64 {
        self.options.tolerance
    }

    /// The constraint solver's most iterations.
    #[getter]
    fn iterations(&self) -> usize {
        self.options.iterations
    }

    /// The line search's most iterations.
    #[getter]
    fn ls_iterations(&self) -> usize {
        self.options.ls_iterations
    }

    /// The line search's tolerance.
    #[getter]
    fn ls_tolerance(&self) -> f64 {
        self.options.ls_tolerance
    }

    /// The no-slip solver's iterations (0: not run).
    #[getter]
    fn noslip_iterations(&self) -> usize {
        self.options.noslip_iterations
    }

    /// The no-slip solver's tolerance.
    #[getter]
    fn noslip_tolerance(&self) -> f64 {
        self.options.noslip_tolerance
    }

    /// The flags the file disables (of those on by default), in its order.
    #[getter]
    fn disabled(&self) -> Vec<String> {
        self.options.disabled.clone()
    }

    /// The flags the file enables (of those off by default), in its order.
    #[getter]
    fn enabled(&self) -> Vec<String> {
        self.options.enabled.clone()
    }

    /// The contact override's margin (m; used when the `override` flag is enabled).
    #[getter]
    fn o_margin(&self) -> f64 {
        self.options.override_margin
    }

    /// The contact override's `solref`.
    #[getter]
    fn o_solref(&self) -> Vec<f64> {
        self.options.override_solver.solref.to_vec()
    }

    /// The contact override's `solimp`.
    #[getter]
    fn o_solimp(&self) -> Vec<f64> {
        self.options.override_solver.solimp.to_vec()
    }

    /// The contact override's friction: sliding ×2, torsional, rolling ×2.
    #[getter]
    fn o_friction(&self) -> Vec<f64> {
        self.options.override_friction.to_vec()
    }

    /// Whether flag `name` (an MJCF `<flag>` attribute, such as "contact" or "energy") is on.
    fn flag(&self, name: &str) -> PyResult<bool> {
        if !DISABLE_FLAGS.contains(&name) && !ENABLE_FLAGS.contains(&name) {
            let known: Vec<&str> = DISABLE_FLAGS.iter().chain(&ENABLE_FLAGS).copied().collect();
            return Err(PyValueError::new_err(format!(
                "argument 'name': unknown flag '{name}', expected one of {}",
                known.join(", ")
            )));
        }
        Ok(self.options.flag(name))
    }

    fn __repr__(&self) -> String {
        let o = &self.options;
        let names = |flags: &[String]| {
            let quoted: Vec<String> = flags.iter().map(|f| format!("'{f}'")).collect();
            format!("[{}]", quoted.join(", "))
        };
        format!(
            "Options(timestep={:?}, integrator='{}', cone='{}', solver='{}', impratio={:?}, \
             tolerance={:?}, iterations={}, disabled={}, enabled={})",
            o.timestep,
            o.integrator.keyword(),
            self.cone(),
            solver_name(o.solver),
            o.impratio,
            o.tolerance,
            o.iterations,
            names(&o.disabled),
            names(&o.enabled)
        )
    }
}

impl PyModel {
    /// The index of the geom named by argument `argument`.
    fn geom_index(&self, argument: &str, name: &Bound<PyAny>) -> PyResult<usize> {
        let name = text(argument, name)?;
        let geoms = &self.model.geoms;
        geoms.iter().position(|g| g.name == name).ok_or_else(|| {
            let names: Vec<String> = geoms.iter().map(|g| format!("'{}'", g.name)).collect();
            PyValueError::new_err(format!(
                "argument '{argument}': no geom is called '{name}'; the model's geoms: [{}]",
                names.join(", ")
            ))
        })
    }
}

/// `solref` and `solimp` into `item` under `solref_key` and `solimp_key`.
fn set_solver(
    item: &Bound<PyDict>,
    (solref_key, solimp_key): (&str, &str),
    solver: &SolverParameters,
) -> PyResult<()> {
    item.set_item(solref_key, solver.solref.to_vec())?;
    item.set_item(solimp_key, solver.solimp.to_vec())
}

#[pymethods]
impl PyModel {
    /// How the model file asks to be simulated (MJCF `<option>`), as a read-only `Options`.
    #[getter]
    fn options(&self) -> PyOptions {
        PyOptions {
            options: self.model.options.clone(),
        }
    }

    /// The collision shapes (MJCF geoms, in the file's order), one dict each: `name`, `body`
    /// (index into `["world"] + body_names`, the body it moves with), `source_body` (the name of
    /// the file's body that holds it; bodies without joints move with their parent), `placement`
    /// (4x4 pose in `body`), `kind` and `size` (as in `visuals`), `contype`, `conaffinity`,
    /// `condim`, `priority`, `friction` (sliding, torsional, rolling), `solmix`, `solref`,
    /// `solimp`, `margin`, `gap`, `element` (where it is written). robodyn does not compute
    /// contacts yet.
    #[getter]
    fn geoms<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let model = &self.model;
        let mut geoms = Vec::with_capacity(model.geoms.len());
        for geom in &model.geoms {
            let item = PyDict::new(py);
            item.set_item("name", &geom.name)?;
            item.set_item("body", geom.body)?;
            item.set_item("source_body", &model.source_bodies[geom.source_body].name)?;
            item.set_item("placement", matrix(py, &geom.placement.to_homogeneous())?)?;
            item.set_item("kind", geom.shape.kind())?;
            item.set_item("size", shape_size(&geom.shape))?;
            item.set_item("contype", geom.contype)?;
            item.set_item("conaffinity", geom.conaffinity)?;
            item.set_item("condim", geom.contact.condim)?;
            item.set_item("priority", geom.priority)?;
            item.set_item("friction", geom.friction.to_vec())?;
            item.set_item("solmix", geom.solmix)?;
            set_solver(&item, ("solref", "solimp"), &geom.contact.solver)?;
            item.set_item("margin", geom.contact.margin)?;
            item.set_item("gap", geom.contact.gap)?;
            item.set_item("element", &geom.element)?;
            geoms.push(item);
        }
        Ok(geoms)
    }

    /// The geom pairs the file asks to be checked for contact (MJCF `<contact><pair>`), one dict
    /// each: `name`, `geom1`, `geom2` (names), `condim`, `friction` (sliding ×2, torsional,
    /// rolling ×2), `solref`, `solreffriction`, `solimp`, `margin`, `gap`.
    #[getter]
    fn contact_pairs<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let model = &self.model;
        let mut pairs = Vec::with_capacity(model.contact_pairs.len());
        for pair in &model.contact_pairs {
            let item = PyDict::new(py);
            item.set_item("name", &pair.name)?;
            item.set_item("geom1", &model.geoms[pair.geoms.0].name)?;
            item.set_item("geom2", &model.geoms[pair.geoms.1].name)?;
            item.set_item("condim", pair.contact.condim)?;
            item.set_item("friction", pair.friction.to_vec())?;
            set_solver(&item, ("solref", "solimp"), &pair.contact.solver)?;
            item.set_item("solreffriction", pair.solreffriction.to_vec())?;
            item.set_item("margin", pair.contact.margin)?;
            item.set_item("gap", pair.contact.gap)?;
            pairs.push(item);
        }
        Ok(pairs)
    }

    /// The geom pairs MuJoCo would check for contact besides `contact_pairs` (its "dynamic"
    /// pairs: different moving bodies, not parent and child unless the `filterparent` flag is
    /// disabled, not excluded, `contype` and `conaffinity` sharing a bit), as (geom1, geom2)
    /// names in MuJoCo's order.
    #[getter]
    fn contact_candidates(&self) -> Vec<(String, String)> {
        let geoms = &self.model.geoms;
        robodyn::collision::candidate_pairs(&self.model)
            .into_iter()
            .map(|(i, j)| (geoms[i].name.clone(), geoms[j].name.clone()))
            .collect()
    }

    /// The parameters a contact between geoms `geom1` and `geom2` (names) takes, as MuJoCo sets
    /// them: their explicit pair's if they form one, else the two geoms' mixed (the higher
    /// `priority`'s, or `condim` and `friction` the larger, `solref` and `solimp` weighted by
    /// `solmix`), margins and gaps added, the `<option>` override applied where enabled. A dict:
    /// `condim`, `friction` (sliding ×2, torsional, rolling ×2), `solref`, `solreffriction`,
    /// `solimp`, `margin` (MuJoCo's `includemargin`), `gap`.
    fn contact_parameters<'py>(
        &self,
        py: Python<'py>,
        geom1: &Bound<PyAny>,
        geom2: &Bound<PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let first = self.geom_index("geom1", geom1)?;
        let second = self.geom_index("geom2", geom2)?;
        if first == second {
            return Err(PyValueError::new_err(format!(
                "argument 'geom2': expected a geom other than geom1, got '{}' twice",
                self.model.geoms[first].name
            )));
        }
        let parameters = robodyn::soft::contact_parameters(&self.model, first, second);
        let item = PyDict::new(py);
        item.set_item("condim", parameters.condim)?;
        item.set_item("friction", parameters.friction.to_vec())?;
        set_solver(&item, ("solref", "solimp"), &parameters.solver)?;
        item.set_item("solreffriction", parameters.solreffriction.to_vec())?;
        item.set_item("margin", parameters.margin)?;
        item.set_item("gap", parameters.gap)?;
        Ok(item)
    }

    /// The contacts of the model's geoms at configuration `q`, as MuJoCo's collision
    /// detection finds them (its pairs, order, points, frames and distances): a list of dicts,
    /// one per contact: `geom1`, `geom2` (names; `geom1` the geom of lower MuJoCo type: plane,
    /// sphere, capsule, ellipsoid, cylinder, box, mesh), `pair` (the explicit pair's name, or
    /// None), `distance` (signed, m: negative when they overlap), `position` (3,) (midway
    /// between the surfaces), `frame` (3, 3) (rows: the normal from geom1 to geom2, then two
    /// tangents), `normal` (3,). A contact is listed while `distance` is below the pair's
    /// `margin + gap` (`contact_parameters`).
    fn collide<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let model = &self.model;
        let q = read_sample("q", q, SampleShape::vector(model.nq))?;
        let mut data = robodyn::Data::new(model);
        let x_world = robodyn::algo::forward_kinematics(model, &mut data, &q).map_err(to_py_err)?;
        let pairs = robodyn::collision::checked_pairs(model);
        let (mut scratch, mut contacts) = (Default::default(), Vec::new());
        robodyn::collision::collide(model, x_world, &pairs, &mut scratch, &mut contacts);
        contact_dicts(py, model, &contacts)
    }

    /// The contacts (as `collide` lists them) of the geoms placed in the world directly:
    /// `positions` (ngeom, 3) and `rotations` (ngeom, 9), each rotation matrix row by row, its
    /// columns the geom's axes (MuJoCo's `geom_xpos` and `geom_xmat`), in the order of `geoms`.
    fn collide_placed<'py>(
        &self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        rotations: &Bound<'py, PyAny>,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let model = &self.model;
        let count = model.geoms.len();
        let positions = read_sample("positions", positions, SampleShape::matrix(count, 3))?;
        let rotations = read_sample("rotations", rotations, SampleShape::matrix(count, 9))?;
        let rotations: Vec<Matrix3<f64>> = rotations
            .chunks_exact(9)
            .map(Matrix3::from_row_slice)
            .collect();
        for (g, rotation) in rotations.iter().enumerate() {
            let error = (rotation.transpose() * rotation - Matrix3::identity())
                .abs()
                .max();
            if error > ROTATION_TOLERANCE || rotation.determinant() < 0.0 {
                return Err(PyValueError::new_err(format!(
                    "argument 'rotations': expected rotation matrices, row {g} (geom '{}') is \
                     {} (|RᵀR − I| = {error:.1e}, det {:.3})",
                    model.geoms[g].name,
                    rotation.transpose(),
                    rotation.determinant()
                )));
            }
        }
        let place = |g: usize| robodyn::collision::Placed {
            shape: &model.geoms[g].shape,
            rotation: rotations[g],
            position: Vector3::new(positions[3 * g], positions[3 * g + 1], positions[3 * g + 2]),
        };
        let pairs = robodyn::collision::checked_pairs(model);
        let (mut touches, mut contacts) = (Vec::new(), Vec::new());
        robodyn::collision::collide_placed(model, place, &pairs, &mut touches, &mut contacts);
        contact_dicts(py, model, &contacts)
    }

    /// The file's body pairs whose geoms never touch (MJCF `<contact><exclude>`), as
    /// (body1, body2) names.
    #[getter]
    fn contact_excludes(&self) -> Vec<(String, String)> {
        let names = &self.model.source_bodies;
        self.model
            .contact_excludes
            .iter()
            .map(|e| (names[e.first].name.clone(), names[e.second].name.clone()))
            .collect()
    }

    /// Each joint's limit and dry friction in MuJoCo's soft constraint model, one dict per joint
    /// (in `joint_names`' order): `solreflimit`, `solimplimit`, `margin`, `solreffriction`,
    /// `solimpfriction` (MuJoCo's defaults for a model from another format).
    #[getter]
    fn joint_softness<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut joints = Vec::new();
        for softness in self.model.joint_softness.iter().skip(1) {
            let item = PyDict::new(py);
            set_solver(&item, ("solreflimit", "solimplimit"), &softness.limit)?;
            item.set_item("margin", softness.margin)?;
            set_solver(
                &item,
                ("solreffriction", "solimpfriction"),
                &softness.friction,
            )?;
            joints.push(item);
        }
        Ok(joints)
    }
}

/// How far a rotation given to `collide_placed` may be from orthonormal: far looser than the
/// rounding of any rotation a program computes (MuJoCo's `geom_xmat` is orthonormal to ~1e-15),
/// far tighter than a matrix that is not one.
const ROTATION_TOLERANCE: f64 = 1e-9;

/// The contacts as Python dicts (see `collide`).
pub(crate) fn contact_dicts<'py>(
    py: Python<'py>,
    model: &robodyn::Model,
    contacts: &[robodyn::collision::Contact],
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let mut items = Vec::with_capacity(contacts.len());
    for contact in contacts {
        let item = PyDict::new(py);
        item.set_item("geom1", &model.geoms[contact.geoms.0].name)?;
        item.set_item("geom2", &model.geoms[contact.geoms.1].name)?;
        let pair = contact.pair.map(|k| model.contact_pairs[k].name.clone());
        item.set_item("pair", pair)?;
        item.set_item("distance", contact.distance)?;
        item.set_item(
            "position",
            PyArray1::from_slice(py, contact.position.as_slice()),
        )?;
        let normal = contact.frame.row(0).transpose();
        item.set_item("normal", PyArray1::from_slice(py, normal.as_slice()))?;
        let rows: Vec<Vec<f64>> = contact
            .frame
            .row_iter()
            .map(|row| row.iter().copied().collect())
            .collect();
        item.set_item("frame", PyArray2::from_vec2(py, &rows)?)?;
        items.push(item);
    }
    Ok(items)
}

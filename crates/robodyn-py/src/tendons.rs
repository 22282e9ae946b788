//! The model file's tendons (MJCF `<tendon>`: fixed, and spatial through sites and pulleys):
//! their names and lengths.

use crate::model::*;
use pyo3::prelude::*;
use robodyn::soft::tendons::TendonKinematics;

#[pymethods]
impl PyModel {
    /// The tendons' names, in the file's order (`tendon<k>` where the file gives none).
    #[getter]
    fn tendon_names(&self) -> Vec<String> {
        self.model.tendons.iter().map(|t| t.name.clone()).collect()
    }

    /// Each tendon's spring yield (MJCF `springyield`; 0: elastic), in the file's order.
    #[getter]
    fn tendon_spring_yield(&self) -> Vec<f64> {
        self.model.tendons.iter().map(|t| t.spring_yield).collect()
    }

    /// The tendons' lengths (ntendon,) at q (MuJoCo's `ten_length`): `L = Σ coef q_j` over a
    /// fixed tendon's joints, the length of its path through its sites for a spatial one (each
    /// branch after a pulley divided by its divisor). A batch gives (N, ntendon).
    fn tendon_lengths<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[self.model.tendons.len()],
            &|m, workspace, i, out| {
                let kinematics = TendonKinematics::at(m, &mut workspace.data, i[0])?;
                out.copy_from_slice(&kinematics.lengths);
                Ok(())
            },
        )
    }
}

//! The model file's fixed tendons (MJCF `<tendon><fixed>`): their names and lengths.

use crate::model::*;
use pyo3::prelude::*;

#[pymethods]
impl PyModel {
    /// The fixed tendons' names, in the file's order (`tendon<k>` where the file gives none).
    #[getter]
    fn tendon_names(&self) -> Vec<String> {
        self.model.tendons.iter().map(|t| t.name.clone()).collect()
    }

    /// The fixed tendons' lengths (ntendon,) at q: `L = Σ coef q_j` over each one's joints
    /// (MuJoCo's `ten_length`). A batch gives (N, ntendon).
    fn tendon_lengths<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate(
            py,
            &[self.q_arg("q", q)?],
            &[self.model.tendons.len()],
            &|m, _, i, out| {
                m.check_configuration(i[0])?;
                for (length, tendon) in out.iter_mut().zip(&m.tendons) {
                    *length = tendon.length(m, i[0]);
                }
                Ok(())
            },
        )
    }
}

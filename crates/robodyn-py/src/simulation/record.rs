//! The trajectories of a simulation as the dict of NumPy arrays that `robodyn.simulate` unpacks.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::integrate::{AccuracyIssue, AccuracyMeasure, Trajectory};
use robodyn::Model;

/// One recorded series of a trajectory.
type Series = fn(&Trajectory) -> &Vec<f64>;

/// One trajectory's arrays into `out`: t, q, v, a, tau, tau_passive, stacked over rollouts.
pub(super) fn stack<'py>(
    py: Python<'py>,
    model: &Model,
    runs: &[Trajectory],
    batch: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let samples = runs[0].len();
    let fields: [(&str, Series, usize); 6] = [
        ("t", |r| &r.t, 0),
        ("q", |r| &r.q, model.nq),
        ("v", |r| &r.v, model.nv),
        ("a", |r| &r.a, model.nv),
        ("tau", |r| &r.tau, model.nv),
        ("tau_passive", |r| &r.tau_passive, model.nv),
    ];
    for (name, field, width) in fields {
        let flat: Vec<f64> = if name == "t" {
            runs[0].t.clone()
        } else {
            runs.iter().flat_map(|r| field(r).iter().copied()).collect()
        };
        let mut shape = Vec::new();
        if batch && name != "t" {
            shape.push(runs.len());
        }
        shape.push(samples);
        if width > 0 {
            shape.push(width);
        }
        out.set_item(name, PyArray1::from_vec(py, flat).reshape(shape)?)?;
    }
    // statistics per rollout
    let each = |f: fn(&Trajectory) -> usize| runs.iter().map(f).collect::<Vec<usize>>();
    out.set_item("steps", each(|r| r.statistics.steps))?;
    out.set_item("rejected_steps", each(|r| r.statistics.rejected_steps))?;
    out.set_item("evaluations", each(|r| r.statistics.evaluations))?;
    // the accuracy record per rollout
    let accuracy = |f: fn(&Trajectory) -> &Vec<f64>| -> Vec<Bound<'py, PyArray1<f64>>> {
        runs.iter()
            .map(|r| PyArray1::from_slice(py, f(r)))
            .collect()
    };
    out.set_item("error_times", accuracy(|r| &r.accuracy.check_times))?;
    out.set_item("error_estimate", accuracy(|r| &r.accuracy.local_errors))?;
    let drifts: Vec<Option<f64>> = runs.iter().map(|r| r.accuracy.energy_drift).collect();
    out.set_item("energy_drift", drifts)?;
    let issues = runs
        .iter()
        .map(|r| {
            r.accuracy
                .issue
                .map(|issue| accuracy_issue(py, &issue))
                .transpose()
        })
        .collect::<PyResult<Vec<_>>>()?;
    out.set_item("accuracy_issue", issues)?;
    Ok(out)
}

/// An accuracy issue as `{"message", "measure", "time", "error", "largest_step"}`.
fn accuracy_issue<'py>(py: Python<'py>, issue: &AccuracyIssue) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("message", issue.to_string())?;
    let measure = match issue.measure {
        AccuracyMeasure::LocalError => "local_error",
        AccuracyMeasure::EnergyDrift => "energy_drift",
    };
    out.set_item("measure", measure)?;
    out.set_item("time", issue.time)?;
    out.set_item("error", issue.error)?;
    out.set_item("largest_step", issue.largest_step)?;
    Ok(out)
}

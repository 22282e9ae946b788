//! The one evaluation path every numeric method takes: the arguments' common batch, their values
//! in place or copied, then one sample in the caller's thread or a batch on all cores.

use super::output::{output_array, Target};
use super::pages::advise_huge_pages;
use super::schedule::{run_kernel, BatchInputs, Kernel, LaneRun, MAX_ARGUMENTS};
use super::workspace::Workspace;
use super::PyModel;
use crate::args::{shape_text, Argument};
use crate::results::new_array;
use crate::to_py_err;
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use robodyn::algo::BatchAlgorithm;

impl PyModel {
    /// Runs `kernel` on one sample or a batch of the `arguments`, producing `output_shape` per
    /// sample.
    pub(crate) fn evaluate<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        output_shape: &[usize],
        kernel: &Kernel,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.evaluate_to(py, arguments, output_shape, Target::Zeros, kernel, None)
    }

    /// [`Self::evaluate`] for a kernel that writes every value of its result: into the caller's
    /// array `out` when one is given (checked by [`output_array`]), returned, so that a loop can
    /// reuse its result array; else into a new array not zeroed first. A batch runs the kernel in
    /// `lanes` (when given) on each thread's run of samples instead of `kernel` on one sample at
    /// a time.
    pub(crate) fn evaluate_into<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        output_shape: &[usize],
        out: Option<&Bound<'py, PyAny>>,
        kernel: &Kernel,
        lanes: Option<BatchAlgorithm>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let lanes = lanes.map(LaneRun::Algorithm);
        self.evaluate_to(py, arguments, output_shape, Target::Out(out), kernel, lanes)
    }

    /// [`Self::evaluate_into`] with the result's array chosen by `target`.
    pub(crate) fn evaluate_to<'py>(
        &self,
        py: Python<'py>,
        arguments: &[Argument<'py>],
        output_shape: &[usize],
        target: Target<'_, 'py>,
        kernel: &Kernel,
        lanes: Option<LaneRun>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (out, zeroed) = match target {
            Target::Zeros => (None, true),
            Target::Out(out) => (out, false),
        };
        let batch = common_batch(arguments)?;
        // the inputs in place, or copies of the strided ones, each argument looked at once (plain
        // loops: through an array of `Cow`s made by `array::from_fn`, each came back through
        // memory and was copied again)
        let mut in_place: [Option<&[f64]>; MAX_ARGUMENTS] = [None; MAX_ARGUMENTS];
        let mut copies: [Vec<f64>; MAX_ARGUMENTS] = Default::default();
        for ((place, copy), argument) in in_place.iter_mut().zip(&mut copies).zip(arguments) {
            *place = argument.contiguous_values();
            if place.is_none() {
                *copy = argument.copied_values();
            }
        }
        let mut values: [&[f64]; MAX_ARGUMENTS] = [&[]; MAX_ARGUMENTS];
        for ((value, place), copy) in values.iter_mut().zip(in_place).zip(&copies) {
            *value = place.unwrap_or(copy);
        }
        let values = &values[..arguments.len()];
        let target = match out {
            Some(out) => Some(output_array(out, batch, output_shape, arguments, values)?),
            None => None,
        };
        let output_size: usize = output_shape.iter().product();
        let model = &self.model;
        match batch {
            None => {
                let given = target.is_some();
                let output = match target {
                    Some(target) => target,
                    None => new_array(py, output_shape, zeroed)?,
                };
                // SAFETY: a new array nothing else refers to yet, or the caller's, checked to
                // share no memory with an input
                let out = unsafe { output.as_slice_mut() }
                    .map_err(|e| PyValueError::new_err(e.to_string()))?;
                match self.workspace.try_lock() {
                    Ok(mut workspace) => run_kernel(kernel, model, &mut workspace, values, out),
                    Err(_) => run_kernel(kernel, model, &mut Workspace::new(model), values, out),
                }
                .map_err(to_py_err)?;
                if output_shape.is_empty() && !given {
                    return output.get_item(());
                }
                Ok(output.into_any())
            }
            Some(n) => {
                let sizes: [usize; MAX_ARGUMENTS] = std::array::from_fn(|k| {
                    arguments
                        .get(k)
                        .map_or(0, |a| a.sample_shape.as_slice().iter().product())
                });
                let batch = BatchInputs {
                    values,
                    sizes: &sizes[..values.len()],
                    output_size,
                };
                if let Some(output) = target {
                    // SAFETY: as for one sample
                    let out = unsafe { output.as_slice_mut() }
                        .map_err(|e| PyValueError::new_err(e.to_string()))?;
                    self.run_batch(py, &batch, out, kernel, lanes)?;
                    return Ok(output.into_any());
                }
                let mut out = vec![0.0; n * output_size];
                advise_huge_pages(&mut out);
                self.run_batch(py, &batch, &mut out, kernel, lanes)?;
                let shape: Vec<usize> = std::iter::once(n)
                    .chain(output_shape.iter().copied())
                    .collect();
                Ok(PyArray1::from_vec(py, out).reshape(shape)?.into_any())
            }
        }
    }
}

/// The batch size the arguments share (`None`: one sample each), or an error naming the first
/// argument that differs.
fn common_batch(arguments: &[Argument]) -> PyResult<Option<usize>> {
    let batch = arguments[0].batch()?;
    for argument in &arguments[1..] {
        if argument.batch()? != batch {
            return Err(PyValueError::new_err(format!(
                "argument '{}': expected {} like argument '{}', got shape {}",
                argument.name,
                match batch {
                    None => "a single sample".to_string(),
                    Some(n) => format!("a batch of {n}"),
                },
                arguments[0].name,
                shape_text(argument.array.shape())
            )));
        }
    }
    Ok(batch)
}

//! The bundled models against Pinocchio's outputs, and the closed forms of the symbolic layer
//! (`python -m robodyn.symbolic.fixtures`), frozen in testdata/reference/ (see its README).

mod common;

use common::assert_close;
use robodyn::algo::*;
use robodyn::io::{bundled_model, load_dh_file, load_urdf_file, LoadOptions};
use robodyn::Data;
use serde_json::Value;

/// Agreement with Pinocchio, relative to the field's magnitude.
const REFERENCE_TOLERANCE: f64 = 1e-9;
/// Agreement with the exact closed forms evaluated to 30 digits, relative to the field's magnitude.
const CLOSED_FORM_TOLERANCE: f64 = 1e-10;

fn numbers(value: &Value) -> Vec<f64> {
    match value {
        Value::Number(x) => vec![x.as_f64().expect("a number")],
        Value::Array(items) => items.iter().flat_map(numbers).collect(),
        other => panic!("expected numbers, got {other}"),
    }
}

/// A row-major matrix from the JSON as column-major, like nalgebra stores it.
fn column_major(value: &Value) -> Vec<f64> {
    let rows: Vec<Vec<f64>> = value
        .as_array()
        .expect("rows")
        .iter()
        .map(numbers)
        .collect();
    (0..rows[0].len())
        .flat_map(|c| rows.iter().map(move |row| row[c]))
        .collect()
}

#[test]
fn bundled_models_match_frozen_pinocchio_values() {
    for name in robodyn::io::bundled_names() {
        let path = format!(
            "{}/../../testdata/reference/pinocchio_bundled_{name}.json",
            env!("CARGO_MANIFEST_DIR")
        );
        let reference: Value =
            serde_json::from_str(&std::fs::read_to_string(&path).expect("reference file")).unwrap();
        let model = bundled_model(name, false).unwrap();
        let mut data = Data::new(&model);
        assert_eq!(
            numbers(&reference["provenance"]["gravity"]),
            model.gravity.as_slice()
        );
        for (k, state) in reference["states"].as_array().unwrap().iter().enumerate() {
            let label = |field: &str| format!("{name} state {k} {field}");
            let (q, v, a, tau) = (
                numbers(&state["q"]),
                numbers(&state["v"]),
                numbers(&state["a"]),
                numbers(&state["tau"]),
            );
            let result = rnea(&model, &mut data, &q, &v, &a, None).unwrap();
            assert_close(
                &label("rnea"),
                result.as_slice(),
                &numbers(&state["rnea"]),
                REFERENCE_TOLERANCE,
            );
            let result = crba(&model, &mut data, &q).unwrap();
            assert_close(
                &label("M"),
                result.as_slice(),
                &column_major(&state["mass_matrix"]),
                REFERENCE_TOLERANCE,
            );
            let result = generalized_gravity(&model, &mut data, &q).unwrap();
            assert_close(
                &label("g"),
                result.as_slice(),
                &numbers(&state["gravity"]),
                REFERENCE_TOLERANCE,
            );
            let result = bias_forces(&model, &mut data, &q, &v).unwrap();
            assert_close(
                &label("bias"),
                result.as_slice(),
                &numbers(&state["bias"]),
                REFERENCE_TOLERANCE,
            );
            let result = aba(&model, &mut data, &q, &v, &tau, None).unwrap();
            assert_close(
                &label("aba"),
                result.as_slice(),
                &numbers(&state["aba"]),
                REFERENCE_TOLERANCE,
            );
            forward_kinematics(&model, &mut data, &q).unwrap();
            for (frame, pose) in state["frame_poses"].as_object().unwrap() {
                let index = model.frame_index(frame).unwrap();
                let result = frame_placement(&model, &data, index).to_homogeneous();
                assert_close(
                    &label(frame),
                    result.as_slice(),
                    &column_major(pose),
                    REFERENCE_TOLERANCE,
                );
            }
            for (frame, expected) in state["world_jacobians"].as_object().unwrap() {
                let index = model.frame_index(frame).unwrap();
                let result = jacobian(&model, &mut data, &q, index, Reference::World).unwrap();
                assert_close(
                    &label(frame),
                    result.as_slice(),
                    &column_major(expected),
                    REFERENCE_TOLERANCE,
                );
            }
        }
    }
}

#[test]
fn closed_forms_of_the_symbolic_layer_match_the_algorithms() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for name in ["planar2", "pendulum", "rpp_arm", "ur5_dh", "ur5"] {
        let path = root.join(format!("testdata/reference/symbolic_{name}.json"));
        let reference: Value =
            serde_json::from_str(&std::fs::read_to_string(&path).expect("reference file")).unwrap();
        let model_path = root.join(reference["provenance"]["model"].as_str().unwrap());
        let mut model = if model_path.extension().is_some_and(|e| e == "toml") {
            load_dh_file(&model_path).unwrap()
        } else {
            load_urdf_file(&model_path, LoadOptions::default()).unwrap()
        };
        let gravity = numbers(&reference["provenance"]["gravity"]);
        model.gravity = robodyn::spatial::Vec3::from_column_slice(&gravity);
        let mut data = Data::new(&model);
        for (k, state) in reference["states"].as_array().unwrap().iter().enumerate() {
            let label = |field: &str| format!("{name} state {k} {field}");
            let (q, v, a) = (
                numbers(&state["q"]),
                numbers(&state["v"]),
                numbers(&state["a"]),
            );
            let checks: [(&str, Vec<f64>, Vec<f64>); 4] = [
                (
                    "M",
                    crba(&model, &mut data, &q).unwrap().as_slice().to_vec(),
                    column_major(&state["mass_matrix"]),
                ),
                (
                    "C",
                    coriolis_matrix(&model, &mut data, &q, &v)
                        .unwrap()
                        .as_slice()
                        .to_vec(),
                    column_major(&state["coriolis_matrix"]),
                ),
                (
                    "G",
                    generalized_gravity(&model, &mut data, &q)
                        .unwrap()
                        .as_slice()
                        .to_vec(),
                    numbers(&state["gravity"]),
                ),
                (
                    "tau",
                    rnea(&model, &mut data, &q, &v, &a, None)
                        .unwrap()
                        .as_slice()
                        .to_vec(),
                    numbers(&state["tau"]),
                ),
            ];
            for (field, actual, expected) in checks {
                assert_close(&label(field), &actual, &expected, CLOSED_FORM_TOLERANCE);
            }
        }
    }
}

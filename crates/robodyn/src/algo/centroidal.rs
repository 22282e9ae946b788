//! Centroidal momentum: the robot's linear momentum and its angular momentum about the centre of
//! mass, h_G = A_G(q) q̇, and the centroidal momentum matrix A_G (6 x nv, rows [linear; angular]).
//!
//! Reference: D. E. Orin, A. Goswami and S.-H. Lee, "Centroidal dynamics of a humanoid robot",
//! Autonomous Robots 35, 2013; Featherstone (2008) §2.13 for the momentum of a body, h = I v.
//! In world coordinates the spatial momentum about the world origin is h_O = Σ_i ⁰I_i ⁰v_i, and
//! grouping bodies into composites (as CRBA does), the column of velocity coordinate b of body i is
//! I^c_i ⁰S_b. Moving the moment from the origin to the centre of mass c:
//!   linear = l,  angular about c = n_O − c × l.
//! Input: q (nq). Writes `data.x_up`, `data.x_world`, `data.i_c`, `data.s_world`,
//! `data.centroidal_matrix` (6 x nv). Cost: O(n).

use crate::algo::crba::{add_composite_inertias, world_inertias_and_subspaces};
use crate::error::Result;
use crate::model::Model;
use crate::spatial::{Inertia, Vec3};
use crate::Data;
use nalgebra::DMatrix;

/// A_G(q), written into `data.centroidal_matrix`.
pub fn centroidal_momentum_matrix<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DMatrix<f64>> {
    model.check_configuration(q)?;
    world_inertias_and_subspaces(model, data, q);
    add_composite_inertias(model, data);

    // the whole robot: the composites of the bodies on the world
    let mut total = Inertia::ZERO;
    for i in (1..model.nbodies()).filter(|&i| model.parent[i] == 0) {
        total += data.i_c[i];
    }
    let com = if total.mass > 0.0 {
        total.first_moment / total.mass
    } else {
        Vec3::zeros()
    };

    for i in 1..model.nbodies() {
        for b in model.v_range(i) {
            // h = I^c_i S_b: momentum about the world origin per unit q̇_b
            let momentum = data.i_c[i].mul_motion(&data.s_world[b]);
            // angular about the centre of mass: n_O − c × l
            let angular = momentum.angular - com.cross(&momentum.linear);
            for k in 0..3 {
                data.centroidal_matrix[(k, b)] = momentum.linear[k];
                data.centroidal_matrix[(k + 3, b)] = angular[k];
            }
        }
    }
    Ok(&data.centroidal_matrix)
}

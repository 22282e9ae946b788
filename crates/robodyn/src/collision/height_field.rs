//! A height field (MJCF's `<hfield>`): elevations sampled on a grid over a rectangle, a terrain
//! for the other geoms to stand on.
//!
//! Reference: MuJoCo's documentation, "XML Reference", §asset/hfield, and "Computation",
//! §Collision detection (read to understand, written anew here). The field of half-sides
//! `(s₀, s₁)`, top `s₂` and base `s₃` holds `rows × columns` elevations `e` normalised to
//! [0, 1]; sample (r, c) lies at
//! ```text
//!   x = c Δx − s₀,   y = r Δy − s₁,   z = e[r, c] s₂,      Δx = 2s₀/(columns − 1), Δy = 2s₁/(rows − 1)
//! ```
//! (row 0 along −y) and the solid reaches down to z = −s₃. Each grid cell is two triangles, and
//! what lies under a triangle, down to the base, is a triangular prism: contacts are found one
//! prism at a time ([`super::convex::height_field_convex`]).

use crate::io::mesh::TriangleMesh;
use crate::spatial::Vec3;

/// A range of samples below this leaves them unscaled (MuJoCo's `mjEPS`).
pub const FLAT_RANGE: f64 = 1e-14;

/// A height field in its own frame.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HeightField {
    /// Half its sides along x and y (`size[0]`, `size[1]`).
    pub half_extents: [f64; 2],
    /// The height of elevation 1 (`size[2]`).
    pub top: f64,
    /// How far the solid reaches below z = 0 (`size[3]`).
    pub base: f64,
    /// Samples along y.
    pub rows: usize,
    /// Samples along x.
    pub columns: usize,
    /// The elevations in [0, 1], row after row (row 0 along −y).
    pub elevations: Vec<f64>,
}

impl HeightField {
    /// A field of `rows × columns` `samples` (row 0 along −y) scaled to [0, 1] as MuJoCo's
    /// compiler scales them, in single precision: `e = (h − min h)/(max h − min h)`, or
    /// `h − min h` when the range is below [`FLAT_RANGE`]. `size` is MJCF's: half-sides, top,
    /// base.
    pub fn new(
        size: [f64; 4],
        rows: usize,
        columns: usize,
        samples: &[f32],
    ) -> Result<Self, String> {
        if let Some(bad) = size.iter().find(|s| !(**s > 0.0 && s.is_finite())) {
            return Err(format!(
                "attribute 'size': expected four positive numbers, got {bad} among them"
            ));
        }
        if rows < 2 || columns < 2 {
            return Err(format!(
                "expected at least 2 rows and 2 columns of elevations, got {rows} x {columns}"
            ));
        }
        if samples.len() != rows * columns {
            return Err(format!(
                "expected nrow x ncol = {} elevations, got {}",
                rows * columns,
                samples.len()
            ));
        }
        if let Some(bad) = samples.iter().find(|h| !h.is_finite()) {
            return Err(format!("expected finite elevations, got {bad}"));
        }
        let low = samples.iter().copied().fold(f32::INFINITY, f32::min);
        let high = samples.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let range = high - low;
        let scaled = f64::from(range) > FLAT_RANGE;
        let elevations = samples
            .iter()
            .map(|&h| f64::from(if scaled { (h - low) / range } else { h - low }))
            .collect();
        Ok(HeightField {
            half_extents: [size[0], size[1]],
            top: size[2],
            base: size[3],
            rows,
            columns,
            elevations,
        })
    }

    /// The grid's spacing along x and y: `(Δx, Δy)`.
    pub fn spacing(&self) -> (f64, f64) {
        (
            2.0 * self.half_extents[0] / (self.columns - 1) as f64,
            2.0 * self.half_extents[1] / (self.rows - 1) as f64,
        )
    }

    /// The surface's point above sample (`row`, `column`).
    pub fn sample(&self, row: usize, column: usize) -> Vec3 {
        let (dx, dy) = self.spacing();
        Vec3::new(
            dx * column as f64 - self.half_extents[0],
            dy * row as f64 - self.half_extents[1],
            self.elevations[row * self.columns + column] * self.top,
        )
    }

    /// The radius of the smallest sphere about the origin holding the field's box (MuJoCo's
    /// `rbound`): `√(s₀² + s₁² + max(s₂, s₃)²)`.
    pub fn radius(&self) -> f64 {
        let [sx, sy] = self.half_extents;
        (sx * sx + sy * sy + self.top.max(self.base).powi(2)).sqrt()
    }

    /// The field as triangles, for drawing: the surface (two triangles a cell), the four walls
    /// down to the base and the bottom, counter-clockwise seen from outside.
    pub fn triangles(&self) -> TriangleMesh {
        let (rows, columns) = (self.rows, self.columns);
        let mut vertices: Vec<Vec3> = (0..rows)
            .flat_map(|r| (0..columns).map(move |c| (r, c)))
            .map(|(r, c)| self.sample(r, c))
            .collect();
        let at = |r: usize, c: usize| r * columns + c;
        let mut faces = Vec::with_capacity(2 * rows * columns + 4 * (rows + columns));
        for r in 0..rows - 1 {
            for c in 0..columns - 1 {
                faces.push([at(r, c), at(r, c + 1), at(r + 1, c + 1)]);
                faces.push([at(r, c), at(r + 1, c + 1), at(r + 1, c)]);
            }
        }
        // the rim walked counter-clockwise seen from above, each sample with one on the base
        let rim: Vec<usize> = (0..columns - 1)
            .map(|c| at(0, c))
            .chain((0..rows - 1).map(|r| at(r, columns - 1)))
            .chain((1..columns).rev().map(|c| at(rows - 1, c)))
            .chain((1..rows).rev().map(|r| at(r, 0)))
            .collect();
        let first_below = vertices.len();
        for &k in &rim {
            let v = vertices[k];
            vertices.push(Vec3::new(v.x, v.y, -self.base));
        }
        let n = rim.len();
        for i in 0..n {
            let j = (i + 1) % n;
            let (upper, next_upper) = (rim[i], rim[j]);
            let (lower, next_lower) = (first_below + i, first_below + j);
            faces.push([upper, lower, next_lower]);
            faces.push([upper, next_lower, next_upper]);
        }
        // the bottom, a fan about its first corner, facing down
        for i in 1..n - 1 {
            faces.push([first_below, first_below + i + 1, first_below + i]);
        }
        TriangleMesh { vertices, faces }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elevations_are_scaled_to_the_unit_interval_in_single_precision() {
        let field =
            HeightField::new([1.0, 2.0, 0.5, 0.1], 2, 3, &[1.0, 2.0, 3.0, 0.3, 5.0, 1.0]).unwrap();
        let range = 5.0f32 - 0.3;
        let expected: Vec<f64> = [1.0f32, 2.0, 3.0, 0.3, 5.0, 1.0]
            .iter()
            .map(|&h| f64::from((h - 0.3) / range))
            .collect();
        assert_eq!(field.elevations, expected);
        assert_eq!(field.elevations[3], 0.0);
        assert_eq!(field.elevations[4], 1.0);
        // the corners of the rectangle, and the top at elevation 1
        assert_eq!(
            field.sample(0, 0),
            Vec3::new(-1.0, -2.0, field.elevations[0] * 0.5)
        );
        assert_eq!(field.sample(1, 1), Vec3::new(0.0, 2.0, 0.5));
        let flat = HeightField::new([1.0, 1.0, 1.0, 1.0], 2, 2, &[3.0; 4]).unwrap();
        assert_eq!(flat.elevations, vec![0.0; 4]);
    }

    #[test]
    fn bad_sizes_and_samples_are_refused() {
        let samples = [0.0f32; 4];
        assert!(HeightField::new([1.0, 1.0, 0.0, 1.0], 2, 2, &samples)
            .unwrap_err()
            .contains("positive"));
        assert!(HeightField::new([1.0; 4], 1, 4, &samples)
            .unwrap_err()
            .contains("at least 2"));
        assert!(HeightField::new([1.0; 4], 2, 3, &samples)
            .unwrap_err()
            .contains("6 elevations, got 4"));
        assert!(HeightField::new([1.0; 4], 2, 2, &[0.0, f32::NAN, 0.0, 0.0])
            .unwrap_err()
            .contains("finite"));
    }

    #[test]
    fn the_drawn_field_is_closed_and_faces_outward() {
        let field = HeightField::new(
            [1.0, 0.5, 0.2, 0.1],
            3,
            4,
            &[0.0, 1.0, 2.0, 3.0, 1.0, 0.5, 0.0, 2.0, 1.0, 1.0, 3.0, 0.0],
        )
        .unwrap();
        let mesh = field.triangles();
        // every edge is shared by exactly two faces, in opposite directions
        let mut edges = std::collections::HashMap::new();
        for f in &mesh.faces {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &count) in &edges {
            assert_eq!(count, 1);
            assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} is not shared");
        }
        // the enclosed volume (divergence theorem) is positive: the faces point outward
        let volume: f64 = mesh
            .faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|k| mesh.vertices[k]);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum();
        assert!(volume > 0.0);
        // above the base: 2 x 1 of floor plus the surface's mean height, at least
        assert!(volume > 2.0 * 1.0 * 0.1);
    }
}

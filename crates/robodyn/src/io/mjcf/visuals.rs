//! What an MJCF geom looks like: its shape, sized as MuJoCo sizes it, coloured as MuJoCo colours
//! it: the geom's `rgba` when it differs from MuJoCo's default, else its `material`'s, else the
//! default grey.

use super::Reader;
use crate::error::Result;
use crate::spatial::Vec3;
use crate::visual::{Shape, DEFAULT_RGBA};
use roxmltree::Node;

/// A material's colour when it gives none (MuJoCo's default).
const MATERIAL_RGBA: [f64; 4] = [1.0, 1.0, 1.0, 1.0];

impl<'a> Reader<'a> {
    /// The shape of a geom of type `kind` and `size` (every size positive and finite; a plane's
    /// may be 0, unbounded).
    pub(super) fn geom_shape(
        &self,
        geom: Node<'a, 'a>,
        class: &str,
        kind: &str,
        size: &[f64],
    ) -> Result<Shape> {
        let needed = match kind {
            "sphere" => 1,
            "capsule" | "cylinder" | "plane" => 2,
            "box" | "ellipsoid" => 3,
            "mesh" => {
                let name = self
                    .attribute(geom, class, "mesh")
                    .ok_or_else(|| self.error(geom, "a mesh geom needs a 'mesh' attribute"))?;
                return self.visual_mesh(geom, &name);
            }
            "hfield" => {
                let name = self.attribute(geom, class, "hfield").ok_or_else(|| {
                    self.error(geom, "an hfield geom needs an 'hfield' attribute")
                })?;
                return self.height_field(geom, &name);
            }
            other => {
                return Err(self.error(
                    geom,
                    format!("unknown geom type '{other}': expected plane, sphere, capsule, ellipsoid, cylinder, box, mesh, hfield or sdf"),
                ))
            }
        };
        // a plane may be unbounded (size 0); every other size is positive
        let valid = |x: &f64| x.is_finite() && (*x > 0.0 || (kind == "plane" && *x >= 0.0));
        if size.len() < needed || !size[..needed].iter().all(valid) {
            return Err(self.error(
                geom,
                format!("attribute 'size': a {kind} needs {needed} positive numbers, got {size:?}"),
            ));
        }
        Ok(match kind {
            "sphere" => Shape::Sphere { radius: size[0] },
            "capsule" => Shape::Capsule {
                radius: size[0],
                half_length: size[1],
            },
            "cylinder" => Shape::Cylinder {
                radius: size[0],
                half_length: size[1],
            },
            "plane" => Shape::Plane {
                half_extents: [size[0], size[1]],
            },
            "box" => Shape::Box {
                half_extents: Vec3::new(size[0], size[1], size[2]),
            },
            _ => Shape::Ellipsoid {
                radii: Vec3::new(size[0], size[1], size[2]),
            },
        })
    }

    /// A geom's colour: its `rgba` unless that is MuJoCo's default and it names a material.
    pub(super) fn geom_rgba(&self, geom: Node<'a, 'a>, class: &str) -> Result<[f64; 4]> {
        let own = self.numbers::<4>(geom, class, "rgba")?;
        let material = self.geom_material(geom, class)?;
        let rgba = match (own, material) {
            (Some(rgba), Some(_)) if rgba != DEFAULT_RGBA => rgba,
            (_, Some(material)) => {
                let class = self.declared_class(material, "class", "main")?;
                self.numbers::<4>(material, class, "rgba")?
                    .unwrap_or(MATERIAL_RGBA)
            }
            (own, None) => own.unwrap_or(DEFAULT_RGBA),
        };
        Ok(rgba)
    }

    /// The `<material>` a geom names, if any.
    pub(super) fn geom_material(
        &self,
        geom: Node<'a, 'a>,
        class: &str,
    ) -> Result<Option<Node<'a, 'a>>> {
        match self.attribute(geom, class, "material") {
            None => Ok(None),
            Some(name) => Ok(Some(*self.materials.get(&name).ok_or_else(|| {
                self.error(
                    geom,
                    format!("attribute 'material': no <material name='{name}'> in the <asset>s"),
                )
            })?)),
        }
    }
}

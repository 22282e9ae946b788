//! What a URDF link looks like: its `<visual>`s, each a box, cylinder, sphere or mesh (and the
//! `capsule` some tools write) at its `<origin>`, coloured by its `<material>` (given there or by
//! name at the top of the file, as ROS reads it). Mesh files are found as ROS finds them:
//! `package://NAME/path` in a folder NAME on `ROS_PACKAGE_PATH` or among the URDF file's
//! ancestors (or an ancestor that is itself NAME), `file://` paths, and paths relative to the
//! URDF file's folder. A mesh not found does not stop the load; the viewer reports it.

use super::Parser;
use crate::error::Result;
use crate::model::ModelBuilder;
use crate::spatial::{Transform, Vec3};
use crate::visual::{MeshSource, Shape, Visual, DEFAULT_RGBA};
use nalgebra::Matrix4;
use roxmltree::Node;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

impl<'a> Parser<'a> {
    /// Adds every link's visuals to the body it is on; `placement[l]` is link l's body and
    /// `X_{link←body}`.
    pub(super) fn add_visuals(
        &self,
        builder: &mut ModelBuilder,
        robot: Node<'a, 'a>,
        links: &[super::Link<'a>],
        placement: &[Option<(usize, Transform)>],
    ) -> Result<()> {
        // a material with a colour, at the top or in any visual, can be named anywhere (as in
        // ROS); the top-level ones come first
        let mut materials = HashMap::new();
        let top = robot.children().filter(|c| c.has_tag_name("material"));
        let in_visuals = robot
            .descendants()
            .filter(|c| c.has_tag_name("material") && c.parent() != Some(robot));
        for material in top.chain(in_visuals) {
            if let (Some(name), Some(rgba)) =
                (material.attribute("name"), self.material_color(material)?)
            {
                materials.entry(name).or_insert(rgba);
            }
        }
        let mut undefined = Vec::new();
        for (link, place) in links.iter().zip(placement) {
            let Some((body, link_placement)) = place else {
                continue;
            };
            let visuals = link.node.children().filter(|c| c.has_tag_name("visual"));
            for (k, visual) in visuals.enumerate() {
                builder.add_visual(Visual {
                    name: visual
                        .attribute("name")
                        .map_or_else(|| format!("{}_visual{k}", link.name), str::to_string),
                    body: *body,
                    // X_{visual←body} = X_{visual←link} X_{link←body}
                    placement: self.origin(visual)? * *link_placement,
                    shape: self.visual_shape(visual)?,
                    rgba: self.visual_color(visual, &materials, &mut undefined)?,
                    group: 0,
                    element: self.location(visual),
                    texture: None,
                });
            }
        }
        // ROS draws these in its default colour and says so; so does robodyn
        for (name, first) in undefined {
            builder.warn(format!(
                "{first}: material '{name}' has no <color> and no other <material name='{name}'> \
                 gives one: drawn in grey"
            ));
        }
        Ok(())
    }

    /// A `<material>`'s `<color rgba>`, if it has one.
    fn material_color(&self, material: Node<'a, 'a>) -> Result<Option<[f64; 4]>> {
        match Self::child(material, "color") {
            None => Ok(None),
            Some(color) => {
                if !color.has_attribute("rgba") {
                    return Err(self.missing_attribute(color, "rgba"));
                }
                Ok(Some(self.numbers(color, "rgba", DEFAULT_RGBA)?))
            }
        }
    }

    /// A visual's colour: its material's own colour, else the colour of the material of that name
    /// given elsewhere, else MuJoCo's grey. A name defined nowhere is added to `undefined` (with
    /// where it is first named), once.
    fn visual_color(
        &self,
        visual: Node<'a, 'a>,
        materials: &HashMap<&str, [f64; 4]>,
        undefined: &mut Vec<(&'a str, String)>,
    ) -> Result<[f64; 4]> {
        let Some(material) = Self::child(visual, "material") else {
            return Ok(DEFAULT_RGBA);
        };
        if let Some(rgba) = self.material_color(material)? {
            return Ok(rgba);
        }
        match material.attribute("name") {
            Some(name) => match materials.get(name) {
                Some(rgba) => Ok(*rgba),
                // a texture alone gives no colour
                None if Self::child(material, "texture").is_some() => Ok(DEFAULT_RGBA),
                None => {
                    if !undefined.iter().any(|(known, _)| *known == name) {
                        undefined.push((name, self.location(material)));
                    }
                    Ok(DEFAULT_RGBA)
                }
            },
            None => Ok(DEFAULT_RGBA),
        }
    }

    /// The shape in a visual's `<geometry>`.
    fn visual_shape(&self, visual: Node<'a, 'a>) -> Result<Shape> {
        let geometry = Self::child(visual, "geometry")
            .ok_or_else(|| self.missing_child(visual, "geometry"))?;
        let shape = geometry
            .children()
            .find(|c| c.is_element())
            .ok_or_else(|| {
                self.error(
                    geometry,
                    "expected one of <box>, <cylinder>, <sphere>, <mesh>, got nothing",
                )
            })?;
        let positive = |name: &str| -> Result<f64> {
            let value = self.attribute(shape, name)?;
            let [x] = self.numbers(shape, name, [0.0])?;
            if !(x.is_finite() && x > 0.0) {
                return Err(self.error(
                    shape,
                    format!("attribute '{name}': expected a positive number, got '{value}'"),
                ));
            }
            Ok(x)
        };
        Ok(match shape.tag_name().name() {
            "box" => {
                let text = self.attribute(shape, "size")?;
                let size = Vec3::from(self.numbers(shape, "size", [0.0; 3])?);
                if !size.iter().all(|x| x.is_finite() && *x > 0.0) {
                    return Err(self.error(
                        shape,
                        format!("attribute 'size': expected three positive numbers, got '{text}'"),
                    ));
                }
                Shape::Box {
                    half_extents: size / 2.0,
                }
            }
            "sphere" => Shape::Sphere {
                radius: positive("radius")?,
            },
            tag @ ("cylinder" | "capsule") => {
                let (radius, half_length) = (positive("radius")?, positive("length")? / 2.0);
                if tag == "cylinder" {
                    Shape::Cylinder {
                        radius,
                        half_length,
                    }
                } else {
                    Shape::Capsule {
                        radius,
                        half_length,
                    }
                }
            }
            "mesh" => {
                let uri = self.attribute(shape, "filename")?;
                let scale = Vec3::from(self.numbers(shape, "scale", [1.0; 3])?);
                Shape::Mesh {
                    source: self.find_mesh(shape, uri),
                    file_to_visual: Matrix4::new_nonuniform_scaling(&scale),
                    hull: None,
                }
            }
            other => {
                return Err(self.error(
                    shape,
                    format!(
                    "unknown geometry <{other}>: expected <box>, <cylinder>, <sphere> or <mesh>"
                ),
                ))
            }
        })
    }

    /// The file a mesh `uri` names, or why none was found.
    fn find_mesh(&self, mesh: Node<'a, 'a>, uri: &str) -> MeshSource {
        let folder = Path::new(self.source)
            .is_file()
            .then(|| Path::new(self.source).parent().map(Path::to_path_buf))
            .flatten();
        let candidates = mesh_candidates(uri, folder.as_deref());
        if let Some(found) = candidates.iter().find(|p| p.is_file()) {
            return MeshSource::File(found.clone());
        }
        let tried = if candidates.is_empty() {
            "nowhere: a relative path needs the model loaded from its file".to_string()
        } else {
            candidates
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        MeshSource::Missing(
            self.error(mesh, format!("mesh file '{uri}' not found; tried {tried}"))
                .to_string(),
        )
    }
}

/// Where a mesh `uri` may be, in the order ROS looks (see the module's header).
fn mesh_candidates(uri: &str, folder: Option<&Path>) -> Vec<PathBuf> {
    if let Some(path) = uri.strip_prefix("file://") {
        return vec![PathBuf::from(path)];
    }
    let Some(package_path) = uri
        .strip_prefix("package://")
        .or_else(|| uri.strip_prefix("model://"))
    else {
        let path = Path::new(uri);
        return match (path.is_absolute(), folder) {
            (true, _) => vec![path.to_path_buf()],
            (false, Some(folder)) => vec![folder.join(path)],
            (false, None) => Vec::new(),
        };
    };
    let (package, inside) = package_path.split_once('/').unwrap_or((package_path, ""));
    let ros_paths = std::env::var("ROS_PACKAGE_PATH").unwrap_or_default();
    let roots = ros_paths
        .split(':')
        .filter(|p| !p.is_empty())
        .map(PathBuf::from)
        .chain(
            folder
                .into_iter()
                .flat_map(|f| f.ancestors().map(Path::to_path_buf)),
        );
    let mut candidates = Vec::new();
    for root in roots {
        let mut places = vec![root.join(package).join(inside)];
        if root.file_name().is_some_and(|n| n == package) {
            places.push(root.join(inside));
        }
        for place in places {
            if !candidates.contains(&place) {
                candidates.push(place);
            }
        }
    }
    candidates
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn package_uris_are_looked_for_among_the_ancestors() {
        let candidates = mesh_candidates(
            "package://arm/meshes/base.stl",
            Some(Path::new("/robots/arm/urdf")),
        );
        assert!(candidates.contains(&PathBuf::from("/robots/arm/meshes/base.stl")));
        assert!(candidates.contains(&PathBuf::from("/robots/arm/urdf/arm/meshes/base.stl")));
        assert!(candidates.contains(&PathBuf::from("/arm/meshes/base.stl")));
    }

    #[test]
    fn relative_and_file_uris() {
        let folder = Some(Path::new("/robots/arm"));
        assert_eq!(
            mesh_candidates("meshes/a.dae", folder),
            vec![PathBuf::from("/robots/arm/meshes/a.dae")]
        );
        assert_eq!(
            mesh_candidates("file:///abs/a.stl", folder),
            vec![PathBuf::from("/abs/a.stl")]
        );
        assert!(mesh_candidates("meshes/a.dae", None).is_empty());
    }
}

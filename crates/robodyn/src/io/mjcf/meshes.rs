//! Mesh geoms: the `<asset><mesh>` they name, its file found as MuJoCo finds it (`<compiler
//! meshdir>` or `assetdir`, relative to the main file's folder, or to the folder of the file that
//! names the mesh), read and turned into mass properties once (`io/mesh.rs`), and the geom's
//! inertia: mass = density · volume (or the geom's `mass`), I = mass/volume · I_unit, about the
//! mesh's centre of mass, placed by the geom's pose.

use super::Reader;
use crate::collision::hull::{ConvexHull, MAX_VERTEX_FACES};
use crate::error::Result;
use crate::io::mesh::{read_mesh, reference_map, MeshInertia, MeshMassProperties, TriangleMesh};
use crate::io::xml::parse_number_list;
use crate::spatial::{Inertia, Mat3, Transform, Vec3};
use crate::visual::{MeshSource, Shape};
use roxmltree::Node;
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::Arc;

/// An asset's name: its `name`, else its file's name without the extension, as MuJoCo names
/// an unnamed mesh or texture.
pub(super) fn asset_name(asset: Node) -> Option<String> {
    match (asset.attribute("name"), asset.attribute("file")) {
        (Some(name), _) => Some(name.to_string()),
        (None, Some(file)) => Some(
            std::path::Path::new(file)
                .file_stem()
                .map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
        ),
        (None, None) => None,
    }
}

impl<'a> Reader<'a> {
    /// Remembers every `<mesh>` of an `<asset>` section by name (its `name`, else its file's stem),
    /// and every `<material>` by name.
    pub(super) fn read_assets(&mut self, asset: Node<'a, 'a>) -> Result<()> {
        let children = self.children(asset)?;
        for material in children.iter().filter(|c| c.has_tag_name("material")) {
            if let Some(name) = material.attribute("name") {
                self.materials.insert(name.to_string(), *material);
            }
        }
        for mesh in children.into_iter().filter(|c| c.has_tag_name("mesh")) {
            if let Some(name) = asset_name(mesh) {
                self.meshes.insert(name, mesh);
            }
        }
        Ok(())
    }

    /// The mesh named `name` read from its file (or its `vertex` and `face`) and moved into its
    /// geoms' frame by `refpos`, `refquat` and `scale`, once.
    fn mesh_triangles(&self, geom: Node<'a, 'a>, name: &str) -> Result<Rc<TriangleMesh>> {
        if let Some(triangles) = self.mesh_triangles.borrow().get(name) {
            return Ok(Rc::clone(triangles));
        }
        let mesh = self.mesh_asset(geom, name)?;
        let class = self.declared_class(mesh, "class", "main")?;
        let error = |message: String| self.error(mesh, message);
        let triangles = match mesh.attribute("file") {
            Some(file) => {
                let path = self.find_mesh_file(mesh, file)?;
                let bytes = std::fs::read(&path)
                    .map_err(|e| error(format!("cannot read '{}': {e}", path.display())))?;
                let extension = path
                    .extension()
                    .map_or_else(String::new, |e| e.to_string_lossy().into_owned());
                let file = read_mesh(&bytes, &extension)
                    .map_err(|m| error(format!("{}: {m}", path.display())))?;
                for dropped in &file.dropped_polygons {
                    self.warnings.borrow_mut().push(format!(
                        "{}: '{}': {}",
                        self.location(mesh),
                        path.display(),
                        dropped.describe()
                    ));
                }
                file.mesh
            }
            None => self.inline_mesh(mesh)?,
        };
        let triangles = triangles.closed().map_err(&error)?;
        triangles.check().map_err(&error)?;
        let (refpos, refquat, scale) = self.mesh_reference(mesh, class)?;
        let triangles = Rc::new(triangles.transformed(refpos, refquat, scale));
        self.mesh_triangles
            .borrow_mut()
            .insert(name.to_string(), Rc::clone(&triangles));
        Ok(triangles)
    }

    /// The mesh named `name` as the compiler uses it (mass properties at unit density, principal
    /// frame, bounding box), computed once.
    fn compiled_mesh(&self, geom: Node<'a, 'a>, name: &str) -> Result<CompiledMesh> {
        if let Some(compiled) = self.mesh_cache.borrow().get(name) {
            return Ok(*compiled);
        }
        let triangles = self.mesh_triangles(geom, name)?;
        let mesh = self.mesh_asset(geom, name)?;
        let class = self.declared_class(mesh, "class", "main")?;
        let error = |message: String| self.error(mesh, message);
        let mode = match self.attribute(mesh, class, "inertia") {
            None => MeshInertia::Legacy,
            Some(name) => MeshInertia::from_name(&name).map_err(&error)?,
        };
        // with a vertex limit MuJoCo's hull is qhull's, stopped after that many vertices: the
        // exact hull when it has no more, an approximation robodyn cannot repeat otherwise
        let limit = self
            .numbers::<1>(mesh, class, "maxhullvert")?
            .map(|[n]| n)
            .filter(|&n| n > -1.0);
        let properties = if mode == MeshInertia::Convex {
            // the hull, once: its vertex count against the limit, then its exact inertia
            let hull = triangles.convex_hull().map_err(&error)?;
            let corners = hull.vertices.len();
            if let Some(limit) = limit.filter(|&n| corners as f64 > n) {
                return Err(error(format!(
                    "inertia='convex' with maxhullvert='{limit}': the mesh's convex hull has {corners} vertices, and MuJoCo then takes qhull's hull stopped at {limit}, which robodyn does not repeat: raise maxhullvert to {corners} or more, leave it out, or use another inertia"
                )));
            }
            hull.mass_properties(MeshInertia::Exact)
        } else {
            triangles.mass_properties(mode)
        }
        .map_err(&error)?;
        let (moments, axes) = principal_frame(&properties.inertia);
        // the vertices' bounding box in the principal frame, about the centre of mass
        let mut aabb = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for vertex in &triangles.vertices {
            let local = axes.transpose() * (vertex - properties.com);
            aabb = (aabb.0.inf(&local), aabb.1.sup(&local));
        }
        let compiled = CompiledMesh {
            properties,
            moments,
            axes,
            aabb,
        };
        self.mesh_cache
            .borrow_mut()
            .insert(name.to_string(), compiled);
        Ok(compiled)
    }

    /// The convex hull of the mesh named `name`, what its collision geoms' contacts see
    /// (`collision/hull.rs`), built once.
    fn collision_hull(&self, geom: Node<'a, 'a>, name: &str) -> Result<Arc<ConvexHull>> {
        if let Some(hull) = self.hull_cache.borrow().get(name) {
            return Ok(Arc::clone(hull));
        }
        let triangles = self.mesh_triangles(geom, name)?;
        let mesh = self.mesh_asset(geom, name)?;
        let hull = ConvexHull::new(&triangles).map_err(|m| self.error(mesh, m))?;
        let class = self.declared_class(mesh, "class", "main")?;
        let corners = hull.vertices.len();
        if let Some([limit]) = self.numbers::<1>(mesh, class, "maxhullvert")? {
            if limit > -1.0 && corners as f64 > limit {
                self.warnings.borrow_mut().push(format!(
                    "{}: maxhullvert='{limit}': MuJoCo collides qhull's hull stopped at {limit} vertices, robodyn the whole hull of {corners}: their contacts differ",
                    self.location(mesh)
                ));
            }
        }
        let most = hull.most_faces_at_a_corner();
        if most > MAX_VERTEX_FACES {
            self.warnings.borrow_mut().push(format!(
                "{}: a corner of the mesh's convex hull lies on {most} faces: robodyn's multi-contact considers {MAX_VERTEX_FACES} of them, so a pair touching there may get fewer contacts than in MuJoCo",
                self.location(mesh)
            ));
        }
        let hull = Arc::new(hull);
        self.hull_cache
            .borrow_mut()
            .insert(name.to_string(), Arc::clone(&hull));
        Ok(hull)
    }

    /// A collision geom's shape: a mesh with its convex hull (a mesh whose file is missing
    /// touches nothing: a warning says so); any other shape as it is.
    pub(super) fn collision_shape(
        &self,
        geom: Node<'a, 'a>,
        class: &str,
        shape: Shape,
    ) -> Result<Shape> {
        let Shape::Mesh {
            source,
            file_to_visual,
            ..
        } = shape
        else {
            return Ok(shape);
        };
        if let MeshSource::Missing(why) = &source {
            self.warnings.borrow_mut().push(format!(
                "{}: the geom's mesh file is missing, so nothing touches it ({why})",
                self.location(geom)
            ));
            return Ok(Shape::Mesh {
                source,
                file_to_visual,
                hull: None,
            });
        }
        let name = self
            .attribute(geom, class, "mesh")
            .ok_or_else(|| self.error(geom, "a mesh geom needs a 'mesh' attribute"))?;
        Ok(Shape::Mesh {
            source,
            file_to_visual,
            hull: Some(self.collision_hull(geom, &name)?),
        })
    }

    /// Notes the geoms the `<pair>`s of a `<contact>` section name (before the bodies are read:
    /// such a geom collides whatever its `contype` and `conaffinity`).
    pub(super) fn note_paired_geoms(&mut self, contact: Node<'a, 'a>) -> Result<()> {
        for pair in self.children(contact)? {
            if pair.has_tag_name("pair") {
                for attribute in ["geom1", "geom2"] {
                    if let Some(name) = pair.attribute(attribute) {
                        self.paired_geoms.insert(name.to_string());
                    }
                }
            }
        }
        Ok(())
    }

    /// The `<mesh>` named `name`, for `geom`'s messages.
    fn mesh_asset(&self, geom: Node<'a, 'a>, name: &str) -> Result<Node<'a, 'a>> {
        self.meshes.get(name).copied().ok_or_else(|| {
            self.error(
                geom,
                format!("attribute 'mesh': no <mesh name='{name}'> in the <asset>s"),
            )
        })
    }

    /// A mesh's `refpos`, `refquat` and `scale`.
    fn mesh_reference(&self, mesh: Node<'a, 'a>, class: &str) -> Result<(Vec3, [f64; 4], Vec3)> {
        let vector = |attribute: &str, default: [f64; 3]| -> Result<Vec3> {
            Ok(Vec3::from(
                self.numbers::<3>(mesh, class, attribute)?
                    .unwrap_or(default),
            ))
        };
        let refquat = self
            .numbers::<4>(mesh, class, "refquat")?
            .unwrap_or([1.0, 0.0, 0.0, 0.0]);
        Ok((
            vector("refpos", [0.0; 3])?,
            refquat,
            vector("scale", [1.0; 3])?,
        ))
    }

    /// The mesh named `name` as a visual shape: its file (or the reason it was not found) or
    /// its inline vertices, and the map from their coordinates into the geom's frame. The file
    /// is drawn as written: MuJoCo's re-centring moves the mesh and the geom frame together.
    pub(super) fn visual_mesh(&self, geom: Node<'a, 'a>, name: &str) -> Result<Shape> {
        let mesh = self.mesh_asset(geom, name)?;
        let class = self.declared_class(mesh, "class", "main")?;
        let source = match mesh.attribute("file") {
            Some(file) => match self.find_mesh_file(mesh, file) {
                Ok(path) => MeshSource::File(path),
                Err(missing) => MeshSource::Missing(missing.to_string()),
            },
            None => MeshSource::Inline(self.inline_mesh(mesh)?),
        };
        let (refpos, refquat, scale) = self.mesh_reference(mesh, class)?;
        Ok(Shape::Mesh {
            source,
            file_to_visual: reference_map(refpos, refquat, scale),
            hull: None,
        })
    }

    /// A mesh given in the XML by `vertex` (and `face`: without it, the mesh is the vertices'
    /// convex hull, as in MuJoCo) instead of a file.
    fn inline_mesh(&self, mesh: Node<'a, 'a>) -> Result<TriangleMesh> {
        let numbers = |name: &str| -> Result<Vec<f64>> {
            let Some(text) = mesh.attribute(name) else {
                return match name {
                    "face" => Ok(Vec::new()),
                    _ => Err(self.error(mesh, "expected 'file' or 'vertex', got neither")),
                };
            };
            parse_number_list(text, name).map_err(|m| self.error(mesh, m))
        };
        // the vertices are float32 in MuJoCo, as in a file
        let vertices = numbers("vertex")?
            .chunks_exact(3)
            .map(|v| Vec3::new(v[0] as f32 as f64, v[1] as f32 as f64, v[2] as f32 as f64))
            .collect();
        let faces = numbers("face")?
            .chunks_exact(3)
            .map(|f| [f[0] as usize, f[1] as usize, f[2] as usize])
            .collect();
        TriangleMesh { vertices, faces }
            .closed()
            .map_err(|m| self.error(mesh, m))
    }

    /// Where a mesh file is: see [`Reader::find_asset_file`], under `<compiler meshdir>`.
    fn find_mesh_file(&self, mesh: Node<'a, 'a>, file: &str) -> Result<PathBuf> {
        self.find_asset_file(mesh, file, self.mesh_directory.as_deref(), "mesh")
    }

    /// A primitive fitted to the mesh `mesh` (MuJoCo's `FitGeom`): its size and
    /// X_{primitive←body}. The primitive lies along the mesh's principal axes. By default it fits
    /// the equivalent inertia box: with the principal moments A ≥ B ≥ C (unit density, volume V),
    /// half-sizes b₀ = ½√(6(B + C − A)/V), b₁ = ½√(6(A + C − B)/V), b₂ = ½√(6(A + B − C)/V); sphere
    /// r = (b₀ + b₁ + b₂)/3; capsule r = (b₀ + b₁)/2, half-length max(0, b₂ − r/2); cylinder
    /// r = (b₀ + b₁)/2, half-length b₂; box and ellipsoid (b₀, b₁, b₂); centred on the centre of
    /// mass. With `<compiler fitaabb="true">` it fits the vertices' bounding box in that frame
    /// (half-sizes h, centre c): sphere r = max h; cylinder r = max(h₀, h₁), half-length h₂;
    /// capsule the same less r from the half-length; box and ellipsoid h; centred on c. Each size
    /// is then times the geom's `fitscale`.
    pub(super) fn fitted_primitive(
        &self,
        geom: Node<'a, 'a>,
        class: &str,
        mesh: &str,
        kind: &str,
        frame: &Transform,
    ) -> Result<(Vec<f64>, Transform)> {
        if !matches!(
            kind,
            "sphere" | "capsule" | "cylinder" | "box" | "ellipsoid"
        ) {
            return Err(self.error(geom, format!("a '{kind}' geom cannot be fitted to a mesh")));
        }
        let compiled = self.compiled_mesh(geom, mesh)?;
        let (mut size, centre) = if self.fit_aabb {
            let (low, high) = compiled.aabb;
            let h = (high - low) / 2.0;
            let size = match kind {
                "sphere" => vec![h.max()],
                "cylinder" => vec![h.x.max(h.y), h.z],
                "capsule" => vec![h.x.max(h.y), h.z - h.x.max(h.y)],
                _ => vec![h.x, h.y, h.z],
            };
            (size, (low + high) / 2.0)
        } else {
            let [a, b, c] = compiled.moments;
            let volume = compiled.properties.volume;
            let half = |x: f64| 0.5 * (6.0 * x.max(0.0) / volume).sqrt();
            let (b0, b1, b2) = (half(b + c - a), half(a + c - b), half(a + b - c));
            let size = match kind {
                "sphere" => vec![(b0 + b1 + b2) / 3.0],
                "capsule" => {
                    let radius = (b0 + b1) / 2.0;
                    vec![radius, (b2 - radius / 2.0).max(0.0)]
                }
                "cylinder" => vec![(b0 + b1) / 2.0, b2],
                _ => vec![b0, b1, b2],
            };
            (size, Vec3::zeros())
        };
        let scale = self
            .numbers::<1>(geom, class, "fitscale")?
            .map_or(1.0, |[s]| s);
        for x in &mut size {
            *x *= scale;
        }
        let origin = compiled.properties.com + compiled.axes * centre;
        Ok((size, Transform::from_pose(&compiled.axes, &origin) * *frame))
    }

    /// The inertia of a mesh geom in the body's frame (`frame`: X_{geom←body}).
    pub(super) fn mesh_geom_inertia(
        &self,
        geom: Node<'a, 'a>,
        class: &str,
        frame: &Transform,
        given_mass: Option<f64>,
        density: f64,
    ) -> Result<Inertia> {
        let name = self
            .attribute(geom, class, "mesh")
            .ok_or_else(|| self.error(geom, "a mesh geom needs a 'mesh' attribute"))?;
        if self.attribute(geom, class, "shellinertia").as_deref() == Some("true") {
            return Err(self.error(
                geom,
                "for mesh geoms, inertia is set on the mesh asset (<mesh inertia='shell'>), as in MuJoCo",
            ));
        }
        let properties = self.compiled_mesh(geom, &name)?.properties;
        let mass = given_mass.unwrap_or(density * properties.volume);
        // X_{com←body}: the centre of mass, in the geom's axes
        let at_com = Transform::from_translation(&properties.com) * *frame;
        let inertia = properties.inertia * (mass / properties.volume);
        self.inertia_in_body(geom, mass, &inertia, &at_com)
    }
}

/// A mesh asset as the compiler uses it.
#[derive(Debug, Clone, Copy)]
pub(super) struct CompiledMesh {
    /// Volume (area for a shell), centre of mass and inertia at unit density.
    properties: MeshMassProperties,
    /// Principal moments, largest first.
    moments: [f64; 3],
    /// The principal axes as the columns of a rotation, in the order of `moments`.
    axes: Mat3,
    /// The vertices' bounding box (lowest, highest corner) in the principal frame at the centre
    /// of mass.
    aabb: (Vec3, Vec3),
}

/// Principal moments of a rotational inertia, largest first, and their axes as the columns of a
/// rotation (the third axis flipped if needed to make it right-handed).
fn principal_frame(inertia: &Mat3) -> ([f64; 3], Mat3) {
    let eigen = inertia.symmetric_eigen();
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| eigen.eigenvalues[j].total_cmp(&eigen.eigenvalues[i]));
    let mut axes = Mat3::from_columns(&order.map(|k| eigen.eigenvectors.column(k).into_owned()));
    if axes.determinant() < 0.0 {
        axes.set_column(2, &(-axes.column(2)));
    }
    (order.map(|k| eigen.eigenvalues[k]), axes)
}

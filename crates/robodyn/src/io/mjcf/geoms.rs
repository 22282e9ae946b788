//! An MJCF body's geoms (those in its `<frame>`s too), each placed as MuJoCo places it (`fromto`,
//! a primitive fitted to a mesh) and kept twice: as a visual (what it looks like) and as a
//! collision shape with its contact parameters (`contype`, `conaffinity`, `condim`, `priority`,
//! `friction`, `solmix`, `solref`, `solimp`, `margin`, `gap`; MuJoCo's defaults, a class's values,
//! leading values as MuJoCo reads them). SDF geoms are neither drawn nor collided: a warning
//! names each that could touch.

use super::Reader;
use crate::error::Result;
use crate::model::{
    ContactParameters, Geom, ModelBuilder, SolverParameters, CONTACT_DIMENSIONS,
    DEFAULT_GEOM_FRICTION, DEFAULT_SOLIMP, DEFAULT_SOLREF,
};
use crate::spatial::Transform;
use crate::visual::Visual;
use roxmltree::Node;

impl<'a> Reader<'a> {
    /// Adds the geoms among a body's `elements` to model body `body`, where the body element's
    /// frame is at `to_element` (`X_{element←body}`); `source_body` is the element's MuJoCo body
    /// id.
    pub(super) fn add_geoms(
        &self,
        builder: &mut ModelBuilder,
        elements: &[Node<'a, 'a>],
        class: &str,
        (body, source_body): (usize, usize),
        to_element: Transform,
    ) -> Result<()> {
        let mut geoms = Vec::new();
        self.framed_elements(elements, class, &["geom"], Transform::IDENTITY, &mut geoms)?;
        for (geom, to_frame, frame_class) in geoms {
            let class = self.declared_class(geom, "class", frame_class)?;
            self.warn_unmodelled(geom, class);
            let kind = self.geom_type(geom, class);
            let contype = self.integer(geom, class, "contype", 1)?;
            let conaffinity = self.integer(geom, class, "conaffinity", 1)?;
            if kind == "sdf" {
                if contype != 0 || conaffinity != 0 {
                    self.warnings.borrow_mut().push(format!(
                        "{}: a {kind} geom is not a collision shape robodyn models: nothing \
                         touches it",
                        self.location(geom)
                    ));
                }
                continue;
            }
            if kind == "plane" && body != 0 {
                return Err(self.error(
                    geom,
                    "a plane may only be on a body welded to the world (without joints from it \
                     to the world), as in MuJoCo",
                ));
            }
            let (size, frame) = self.geom_size_and_frame(geom, class, &kind)?;
            let shape = self.geom_shape(geom, class, &kind, &size)?;
            let name = geom
                .attribute("name")
                .map_or_else(|| format!("geom{}", geom.range().start), str::to_string);
            // a mesh that may touch something is collided as its convex hull
            let collides = contype != 0 || conaffinity != 0 || self.paired_geoms.contains(&name);
            let collision_shape = if collides {
                self.collision_shape(geom, class, shape.clone())?
            } else {
                shape.clone()
            };
            // X_{geom←body} = X_{geom←frame} X_{frame←element} X_{element←body}
            let placement = frame * to_frame * to_element;
            builder.add_visual(Visual {
                name: name.clone(),
                body,
                placement,
                shape,
                rgba: self.geom_rgba(geom, class)?,
                group: self.geom_group(geom, class)?,
                element: self.location(geom),
                texture: match self.geom_material(geom, class)? {
                    Some(material) => self.material_texture(material)?,
                    None => None,
                },
            });
            let bits = |value: i64, attribute: &str| {
                i32::try_from(value).map_err(|_| {
                    self.error(
                        geom,
                        format!("attribute '{attribute}': expected a 32-bit integer, got {value}"),
                    )
                })
            };
            builder.add_geom(Geom {
                name,
                body,
                source_body,
                placement,
                shape: collision_shape,
                contype: bits(contype, "contype")?,
                conaffinity: bits(conaffinity, "conaffinity")?,
                priority: bits(self.integer(geom, class, "priority", 0)?, "priority")?,
                friction: self.leading_numbers(
                    geom,
                    class,
                    "geom",
                    "friction",
                    DEFAULT_GEOM_FRICTION,
                )?,
                solmix: self
                    .numbers::<1>(geom, class, "solmix")?
                    .map_or(1.0, |[x]| x),
                contact: self.contact_parameters(geom, class, "geom")?,
                element: self.location(geom),
            });
        }
        Ok(())
    }

    /// `condim`, `solref`, `solimp`, `margin` and `gap` of a geom or pair (`tag`), MuJoCo's
    /// defaults where neither it nor its class gives them; a `condim` MuJoCo refuses is an error.
    pub(super) fn contact_parameters(
        &self,
        element: Node<'a, 'a>,
        class: &str,
        tag: &str,
    ) -> Result<ContactParameters> {
        let condim = self.integer(element, class, "condim", 3)?;
        let condim = usize::try_from(condim)
            .ok()
            .filter(|c| CONTACT_DIMENSIONS.contains(c))
            .ok_or_else(|| {
                self.error(
                    element,
                    format!("attribute 'condim': expected 1, 3, 4 or 6, got {condim}"),
                )
            })?;
        let scalar = |name: &str| -> Result<f64> {
            Ok(self
                .numbers::<1>(element, class, name)?
                .map_or(0.0, |[x]| x))
        };
        Ok(ContactParameters {
            condim,
            solver: SolverParameters {
                solref: self.leading_numbers(element, class, tag, "solref", DEFAULT_SOLREF)?,
                solimp: self.leading_numbers(element, class, tag, "solimp", DEFAULT_SOLIMP)?,
            },
            margin: scalar("margin")?,
            gap: scalar("gap")?,
        })
    }
}

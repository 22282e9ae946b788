//! `<contact>`: `pair`s of geoms to check for contact, with the parameters used as they are
//! (MuJoCo's pair defaults where neither the pair nor its class gives them: a pair does not mix
//! its geoms' parameters), and `exclude`d body pairs.

use super::Reader;
use crate::error::Result;
use crate::model::{ContactExclude, ContactPair, Model, DEFAULT_PAIR_FRICTION};
use roxmltree::Node;

impl<'a> Reader<'a> {
    /// The `<contact>` sections among `sections` into `model.contact_pairs` and
    /// `model.contact_excludes` (after the geoms are read: a pair names two).
    pub(super) fn read_contacts(&self, sections: &[Node<'a, 'a>], model: &mut Model) -> Result<()> {
        for section in sections.iter().filter(|c| c.has_tag_name("contact")) {
            for element in self.children(*section)? {
                match element.tag_name().name() {
                    "pair" => {
                        let pair = self.contact_pair(element, model)?;
                        model.contact_pairs.push(pair);
                    }
                    _ => {
                        let exclude = ContactExclude {
                            first: self.named_source_body(element, "body1", model)?,
                            second: self.named_source_body(element, "body2", model)?,
                        };
                        model.contact_excludes.push(exclude);
                    }
                }
            }
        }
        Ok(())
    }

    fn contact_pair(&self, element: Node<'a, 'a>, model: &Model) -> Result<ContactPair> {
        let class = self.declared_class(element, "class", "main")?;
        let geom = |attribute: &str| {
            let names = model.geoms.iter().map(|g| g.name.as_str());
            self.named_index(element, attribute, "geom", names)
        };
        let geoms = (geom("geom1")?, geom("geom2")?);
        if geoms.0 == geoms.1 {
            return Err(self.error(element, "a pair joins two different geoms, got one twice"));
        }
        if self
            .numbers::<1>(element, class, "adhesion")?
            .is_some_and(|[a]| a != 0.0)
        {
            self.warnings.borrow_mut().push(format!(
                "{}: attribute 'adhesion' not read (robodyn models no adhesion)",
                self.location(element)
            ));
        }
        Ok(ContactPair {
            name: element.attribute("name").unwrap_or_default().to_string(),
            geoms,
            friction: self.leading_numbers(
                element,
                class,
                "pair",
                "friction",
                DEFAULT_PAIR_FRICTION,
            )?,
            contact: self.contact_parameters(element, class, "pair")?,
            solreffriction: self.leading_numbers(
                element,
                class,
                "pair",
                "solreffriction",
                [0.0, 0.0],
            )?,
        })
    }

    /// The MuJoCo body id of the body named by `attribute` (`world` is 0).
    fn named_source_body(
        &self,
        element: Node<'a, 'a>,
        attribute: &str,
        model: &Model,
    ) -> Result<usize> {
        let names = model.source_bodies.iter().map(|b| b.name.as_str());
        self.named_index(element, attribute, "body", names)
    }

    /// The position among `names` of the `kind` named by `element`'s `attribute`, which it must
    /// have.
    fn named_index<'n>(
        &self,
        element: Node<'a, 'a>,
        attribute: &str,
        kind: &str,
        mut names: impl Iterator<Item = &'n str>,
    ) -> Result<usize> {
        let name = element
            .attribute(attribute)
            .ok_or_else(|| self.error(element, format!("missing attribute '{attribute}'")))?;
        names.position(|n| n == name).ok_or_else(|| {
            self.error(
                element,
                format!("attribute '{attribute}': no {kind} is called '{name}'"),
            )
        })
    }
}

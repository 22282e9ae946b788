//! What MuJoCo reads and robodyn does not model: a warning for each such attribute given a
//! value that changes MuJoCo's result (not MuJoCo's default), so that nothing is left out
//! silently. Attributes that change only drawing or bookkeeping are not listed.

use super::actuator_defaults::ACTUATOR_KINDS;
use super::Reader;
use crate::io::xml::parse_number_list;
use roxmltree::Node;

/// What an attribute's default is: at that value it changes nothing.
#[derive(Debug, Clone, Copy)]
enum Neutral {
    /// Numbers, all zero.
    Zero,
    /// A boolean (or `auto`) that is not "true".
    NotTrue,
}

/// An attribute MuJoCo reads and robodyn does not model: the elements it is on, its name, its
/// neutral value, and what robodyn does instead.
struct Unmodelled {
    tags: &'static [&'static str],
    name: &'static str,
    neutral: Neutral,
    instead: &'static str,
}

/// Every unmodelled attribute of the elements robodyn reads.
const UNMODELLED: &[Unmodelled] = &[
    Unmodelled {
        tags: &["body"],
        name: "mocap",
        neutral: Neutral::NotTrue,
        instead: "a mocap body stays where the file places it, welded to its parent",
    },
    Unmodelled {
        tags: &["geom"],
        name: "adhesion",
        neutral: Neutral::Zero,
        instead: "robodyn models no adhesion",
    },
    Unmodelled {
        tags: &["geom"],
        name: "surfacevel",
        neutral: Neutral::Zero,
        instead: "robodyn's contacts see every surface at rest",
    },
    Unmodelled {
        tags: &ACTUATOR_KINDS,
        name: "delay",
        neutral: Neutral::Zero,
        instead: "the control acts at once",
    },
];

impl<'a> Reader<'a> {
    /// A warning for each attribute of `element` (in `class`) that robodyn does not model and
    /// whose value is not MuJoCo's default.
    pub(super) fn warn_unmodelled(&self, element: Node<'a, 'a>, class: &str) {
        let tag = element.tag_name().name();
        for attribute in UNMODELLED.iter().filter(|a| a.tags.contains(&tag)) {
            let Some(text) = self.attribute(element, class, attribute.name) else {
                continue;
            };
            let changes = match attribute.neutral {
                Neutral::Zero => parse_number_list(&text, attribute.name)
                    .map_or(true, |values| values.iter().any(|x| *x != 0.0)),
                Neutral::NotTrue => text == "true",
            };
            if changes {
                self.warnings.borrow_mut().push(format!(
                    "{}: attribute '{}' not modelled ({})",
                    self.location(element),
                    attribute.name,
                    attribute.instead
                ));
            }
        }
    }
}

//! Classes of defaults (`<default>`) and how an element's attributes are looked up: its own,
//! else its class's (MuJoCo's defaults mechanism,
//! <https://mujoco.readthedocs.io/en/stable/modeling.html#default-settings>), with the typed
//! readers every part of the loader uses.

use super::actuator_defaults::{ClassActuator, ACTUATOR_KINDS};
use super::Reader;
use crate::error::Result;
use crate::io::xml::{parse_number_list, parse_numbers};
use roxmltree::Node;
use std::collections::HashSet;

/// The tag under which a class keeps an element's defaults: every actuator element's under
/// `actuator` (a class has one actuator default, [`actuator_defaults`]).
fn defaults_tag(tag: &str) -> &str {
    if ACTUATOR_KINDS.contains(&tag) {
        "actuator"
    } else {
        tag
    }
}

/// Attributes of which an element may give only the first values, the others kept from its class
/// or MuJoCo's defaults (MuJoCo reads `solimp="0.9 0.95"` as the first two of five).
const LEADING_ATTRIBUTES: [&str; 9] = [
    "friction",
    "solref",
    "solimp",
    "solreflimit",
    "solimplimit",
    "solreffriction",
    "solimpfriction",
    "polycoef",
    "o_friction",
];

/// `values` with their first entries replaced by the numbers of `text` (1 to `values.len()`).
fn overlay_numbers(values: &mut [f64], text: &str, name: &str) -> std::result::Result<(), String> {
    let words: Vec<&str> = text.split_whitespace().collect();
    if words.is_empty() || words.len() > values.len() {
        let n = values.len();
        return Err(format!(
            "attribute '{name}': expected 1 to {n} numbers, got '{text}'"
        ));
    }
    for (value, word) in values.iter_mut().zip(words) {
        *value = word
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("attribute '{name}': '{word}' is not a finite number"))?;
    }
    Ok(())
}

impl<'a> Reader<'a> {
    /// A `<default>` element and its nested classes.
    pub(super) fn read_defaults(&mut self, node: Node<'a, 'a>, parent: Option<&str>) -> Result<()> {
        let class = match (node.attribute("class"), parent) {
            (Some(class), _) => class.to_string(),
            (None, None) => "main".to_string(),
            (None, Some(_)) => return Err(self.error(node, "a nested <default> needs a 'class'")),
        };
        // a second top-level <default> adds to "main", as in MuJoCo; a class starts from its parent
        let start = parent.unwrap_or(&class);
        let mut values = self.defaults.get(start).cloned().unwrap_or_default();
        let elements = self.children(node)?;
        let mut actuator = match parent {
            Some(_) => self.class_actuators(parent).next().cloned(),
            None => self.actuator_defaults.get(&class).map(|c| c.raw.clone()),
        }
        .unwrap_or_default();
        let mut seen = HashSet::new();
        for element in elements.iter().filter(|c| !c.has_tag_name("default")) {
            let tag = element.tag_name().name();
            if !seen.insert(tag) {
                let message = format!("a <default> holds one <{tag}>, this is a second");
                return Err(self.error(*element, message));
            }
            if ACTUATOR_KINDS.contains(&tag) {
                actuator = self.raw_actuator(*element, &actuator, self.class_actuators(parent))?;
            }
            let entry = values.entry(defaults_tag(tag).to_string()).or_default();
            for attribute in element.attributes() {
                let (name, mut value) = (attribute.name(), attribute.value().to_string());
                // a leading attribute keeps the inherited values it does not give
                if let Some(inherited) = entry
                    .get(name)
                    .filter(|_| LEADING_ATTRIBUTES.contains(&name))
                {
                    let given = value.split_whitespace().count();
                    let rest: Vec<&str> = inherited.split_whitespace().skip(given).collect();
                    value = format!("{value} {}", rest.join(" ")).trim().to_string();
                }
                entry.insert(name.to_string(), value);
            }
            self.shortcut_ranges(*element, entry)?;
        }
        self.defaults.insert(class.clone(), values);
        let parent = parent.map(str::to_string);
        let class_actuator = ClassActuator {
            raw: actuator,
            parent,
        };
        self.actuator_defaults.insert(class.clone(), class_actuator);
        for child in elements.iter().filter(|c| c.has_tag_name("default")) {
            self.read_defaults(*child, Some(&class))?;
        }
        Ok(())
    }

    /// An attribute of `node`, else from its class (`class`, else the enclosing `childclass`).
    pub(super) fn attribute(&self, node: Node<'a, 'a>, class: &str, name: &str) -> Option<String> {
        if let Some(value) = node.attribute(name) {
            return Some(value.to_string());
        }
        let class = node.attribute("class").unwrap_or(class);
        self.defaults
            .get(class)?
            .get(defaults_tag(node.tag_name().name()))?
            .get(name)
            .cloned()
    }

    /// Up to `N` numbers of attribute `name` of `node`, each source replacing only the values it
    /// gives: MuJoCo's `defaults`, then `tag`'s default in the class in effect (`node`'s `class`,
    /// else `class`), then the element's own.
    pub(super) fn leading_numbers<const N: usize>(
        &self,
        node: Node<'a, 'a>,
        class: &str,
        tag: &str,
        name: &str,
        defaults: [f64; N],
    ) -> Result<[f64; N]> {
        let class = node.attribute("class").unwrap_or(class);
        let inherited = self
            .defaults
            .get(class)
            .and_then(|d| d.get(tag))
            .and_then(|d| d.get(name));
        let mut values = defaults;
        for text in [inherited.map(String::as_str), node.attribute(name)]
            .into_iter()
            .flatten()
        {
            overlay_numbers(&mut values, text, name).map_err(|m| self.error(node, m))?;
        }
        Ok(values)
    }

    /// A number `node` gives itself (an element that takes no defaults, such as `<compiler>`).
    pub(super) fn own_number(&self, node: Node<'a, 'a>, name: &str) -> Result<Option<f64>> {
        node.attribute(name)
            .map(|text| parse_numbers::<1>(text, name).map(|[x]| x))
            .transpose()
            .map_err(|m| self.error(node, m))
    }

    /// An integer attribute of `node` (or its class), `default` when neither gives it.
    pub(super) fn integer(
        &self,
        node: Node<'a, 'a>,
        class: &str,
        name: &str,
        default: i64,
    ) -> Result<i64> {
        match self.attribute(node, class, name) {
            None => Ok(default),
            Some(text) => text.trim().parse::<i64>().map_err(|_| {
                self.error(
                    node,
                    format!("attribute '{name}': expected an integer, got '{text}'"),
                )
            }),
        }
    }

    /// The class named by `node`'s `attribute` (`class`: the one it takes its defaults from;
    /// `childclass`: the one its children default to), else `class`; an unknown class is an error.
    pub(super) fn declared_class<'c>(
        &self,
        node: Node<'a, 'a>,
        attribute: &str,
        class: &'c str,
    ) -> Result<&'c str>
    where
        'a: 'c,
    {
        match node.attribute(attribute) {
            Some(own) if !self.defaults.contains_key(own) => {
                Err(self.error(node, format!("unknown class '{own}'")))
            }
            Some(own) => Ok(own),
            None => Ok(class),
        }
    }

    /// A polynomial spring's or damper's coefficients in attribute `name`'s text (MuJoCo's
    /// "c c₁ c₂": the linear one, then up to two higher ones, `mjNPOLY`); (0, [0, 0]) when not
    /// given, more than three numbers refused as MuJoCo refuses them.
    pub(super) fn spring_polynomial(
        &self,
        node: Node<'a, 'a>,
        name: &str,
        text: Option<&str>,
    ) -> Result<(f64, [f64; 2])> {
        let Some(text) = text else {
            return Ok((0.0, [0.0; 2]));
        };
        let values = parse_number_list(text, name).map_err(|m| self.error(node, m))?;
        match values.as_slice() {
            [] => Ok((0.0, [0.0; 2])),
            [linear, higher @ ..] if higher.len() <= 2 => {
                let mut terms = [0.0; 2];
                terms[..higher.len()].copy_from_slice(higher);
                Ok((*linear, terms))
            }
            more => {
                let message = format!(
                    "attribute '{name}': expected at most 3 numbers (c c₁ c₂), got {}",
                    more.len()
                );
                Err(self.error(node, message))
            }
        }
    }

    pub(super) fn numbers<const N: usize>(
        &self,
        node: Node<'a, 'a>,
        class: &str,
        name: &str,
    ) -> Result<Option<[f64; N]>> {
        self.attribute(node, class, name)
            .map(|text| parse_numbers::<N>(&text, name).map_err(|m| self.error(node, m)))
            .transpose()
    }
}

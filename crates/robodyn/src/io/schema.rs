//! What elements and attributes a model format knows, and the walk that checks a document against
//! it: an unknown name is reported with the nearest known one ("did you mean `<inertial>`?").
//!
//! A schema is a table of elements; an element lists its attributes and the indices of the
//! elements it may contain, so a recursive element (MJCF's `<body>` in a `<body>`) points to itself.

use crate::error::Result;
use roxmltree::Node;

/// One element of a format.
pub(crate) struct SchemaElement {
    pub name: &'static str,
    /// The attributes it takes; `None`: any, and its contents are not checked (an element that is
    /// not robodyn's business, such as URDF's `<gazebo>`).
    pub attributes: Option<&'static [&'static str]>,
    /// Indices into the schema of the elements it may contain.
    pub children: &'static [usize],
}

/// The known name nearest to `name`, when it is near enough to be a typo of it.
pub(crate) fn nearest<'k>(name: &str, known: impl IntoIterator<Item = &'k str>) -> Option<&'k str> {
    let (distance, best) = known
        .into_iter()
        .map(|candidate| (strsim::levenshtein(name, candidate), candidate))
        .min()?;
    (distance <= (name.chars().count() / 3).max(2)).then_some(best)
}

/// "; did you mean <x>?" or nothing.
fn suggestion(name: &str, known: &[&str], brackets: bool) -> String {
    match nearest(name, known.iter().copied()) {
        Some(best) if brackets => format!("; did you mean <{best}>?"),
        Some(best) => format!("; did you mean '{best}'?"),
        None => String::new(),
    }
}

/// What an error about `node`'s missing attribute `name` adds when the element has an attribute
/// the schema does not know that is close to it (the likely typo), else nothing.
pub(crate) fn misspelt_attribute(schema: &[SchemaElement], node: Node, name: &str) -> String {
    let known = schema
        .iter()
        .find(|e| node.has_tag_name(e.name))
        .and_then(|e| e.attributes)
        .unwrap_or(&[]);
    let unknown = node
        .attributes()
        .map(|a| a.name())
        .filter(|a| !known.contains(a));
    match nearest(name, unknown) {
        Some(typo) => format!(" (the element has '{typo}': a misspelling of '{name}'?)"),
        None => String::new(),
    }
}

/// What an error about `node`'s missing child element `<tag>` adds when the element has a child
/// the schema does not know that is close to it, else nothing.
pub(crate) fn misspelt_child(schema: &[SchemaElement], node: Node, tag: &str) -> String {
    let known: Vec<&str> = schema
        .iter()
        .find(|e| node.has_tag_name(e.name))
        .map(|e| e.children.iter().map(|&k| schema[k].name).collect())
        .unwrap_or_default();
    let unknown = node
        .children()
        .filter(|c| c.is_element())
        .map(|c| c.tag_name().name())
        .filter(|c| !known.contains(c));
    match nearest(tag, unknown) {
        Some(typo) => format!(" (it has <{typo}>: a misspelling of <{tag}>?)"),
        None => String::new(),
    }
}

/// The child elements of a node as a format sees them (MJCF replaces each `<include>` by the
/// included file's elements).
pub(crate) type Children<'c, 'a> = dyn Fn(Node<'a, 'a>) -> Result<Vec<Node<'a, 'a>>> + 'c;

/// The child elements of a node, as they stand in the document.
pub(crate) fn element_children<'a>(node: Node<'a, 'a>) -> Result<Vec<Node<'a, 'a>>> {
    Ok(node.children().filter(|c| c.is_element()).collect())
}

/// Checks `node` (an element of kind `schema[index]`) and everything below it. Each unknown child
/// element or attribute goes to `report(node, message)`, which decides whether it is an error.
/// Elements and attributes in an XML namespace (`xacro:…`) are left alone.
pub(crate) fn check<'a>(
    schema: &[SchemaElement],
    index: usize,
    node: Node<'a, 'a>,
    children: &Children<'_, 'a>,
    report: &mut dyn FnMut(Node, String) -> Result<()>,
) -> Result<()> {
    let element = &schema[index];
    let Some(attributes) = element.attributes else {
        return Ok(());
    };
    for attribute in node.attributes() {
        if attribute.namespace().is_none() && !attributes.contains(&attribute.name()) {
            report(
                node,
                format!(
                    "unknown attribute '{}' of <{}>{}",
                    attribute.name(),
                    element.name,
                    suggestion(attribute.name(), attributes, false)
                ),
            )?;
        }
    }
    for child in children(node)? {
        if child.tag_name().namespace().is_some() {
            continue;
        }
        let name = child.tag_name().name();
        match element.children.iter().find(|&&k| schema[k].name == name) {
            Some(&k) => check(schema, k, child, children, report)?,
            None => {
                let known: Vec<&str> = element.children.iter().map(|&k| schema[k].name).collect();
                report(
                    child,
                    format!(
                        "unknown element <{name}> in <{}>{}",
                        element.name,
                        suggestion(name, &known, true)
                    ),
                )?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::nearest;

    #[test]
    fn the_nearest_name_is_suggested_only_for_a_likely_typo() {
        let known = ["inertial", "visual", "collision"];
        assert_eq!(nearest("inertal", known), Some("inertial"));
        assert_eq!(nearest("colision", known), Some("collision"));
        assert_eq!(nearest("gazebo", known), None);
    }
}

//! Helpers shared by the XML loaders (URDF, MJCF): where an element is, and number lists.

use roxmltree::{Document, Node};

/// "file: <element name='...'> (line n)"; an element without a name is shown under its nearest
/// named ancestor below the document's root element, e.g. "<link name='arm'>/<inertial>".
pub(crate) fn location(source: &str, document: &Document, node: Node) -> String {
    let position = document.text_pos_at(node.range().start);
    let tag = |n: Node| match n.attribute("name") {
        Some(name) => format!("<{} name='{name}'>", n.tag_name().name()),
        None => format!("<{}>", n.tag_name().name()),
    };
    let is_top = |n: &Node| n.parent().is_none_or(|p| p.is_root());
    let named_ancestor = node
        .ancestors()
        .skip(1)
        .find(|a| a.is_element() && a.has_attribute("name") && !is_top(a));
    let path = match named_ancestor {
        Some(ancestor) if !node.has_attribute("name") => format!("{}/{}", tag(ancestor), tag(node)),
        _ => tag(node),
    };
    format!("{source}: {path} (line {})", position.row)
}

/// `N` finite numbers separated by white space, or a message naming the attribute.
pub(crate) fn parse_numbers<const N: usize>(text: &str, name: &str) -> Result<[f64; N], String> {
    let values = parse_number_list(text, name)?;
    values
        .try_into()
        .map_err(|_| format!("attribute '{name}': expected {N} numbers, got '{text}'"))
}

/// Any count of finite numbers separated by white space, or a message naming the attribute.
pub(crate) fn parse_number_list(text: &str, name: &str) -> Result<Vec<f64>, String> {
    text.split_whitespace()
        .map(|value| {
            value
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("attribute '{name}': expected finite numbers, got '{text}'"))
        })
        .collect()
}

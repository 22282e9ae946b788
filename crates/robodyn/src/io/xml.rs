//! Helpers shared by the XML loaders (URDF, MJCF): where an element is, and number lists.

use crate::error::Error;
use roxmltree::{Document, Node};

/// The deepest element nesting a model file may have: the loaders walk the tree recursively, and
/// a deeper file is refused rather than overflowing the stack (robot trees are a few dozen levels
/// deep; MuJoCo's XML parser stops at 500).
pub const MAX_NESTING: usize = 200;

/// Refuses a document nested deeper than [`MAX_NESTING`] elements (walked with an explicit
/// stack, so the check itself cannot overflow).
pub(crate) fn check_nesting(source: &str, document: &Document) -> crate::Result<()> {
    let mut pending = vec![(document.root_element(), 1usize)];
    while let Some((node, depth)) = pending.pop() {
        if depth > MAX_NESTING {
            return Err(Error::model(
                location(source, document, node),
                format!("elements nested more than {MAX_NESTING} deep"),
            ));
        }
        pending.extend(
            node.children()
                .filter(|c| c.is_element())
                .map(|c| (c, depth + 1)),
        );
    }
    Ok(())
}

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

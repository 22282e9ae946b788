//! What an MJCF scene's surfaces are painted with: `<texture>`s (PNG files, MuJoCo's builtin
//! checker, gradient and flat patterns with their marks), the `<material>` that lays one on a
//! geom (`texture` or a `<layer role="rgb">`, `texrepeat`, `texuniform`), and the skybox. Only the
//! viewer reads them; what it cannot draw is kept with the reason (see [`TextureImage`]).

use super::Reader;
use crate::error::Result;
use crate::visual::{BuiltinTexture, Texture, TextureImage, TextureKind, TextureMapping};
use roxmltree::Node;
use std::path::PathBuf;

/// MuJoCo's defaults for a texture's colours and the probability of its random dots.
const DEFAULT_RGB1: [f64; 3] = [0.8, 0.8, 0.8];
const DEFAULT_RGB2: [f64; 3] = [0.5, 0.5, 0.5];
const DEFAULT_MARK_RGB: [f64; 3] = [0.0, 0.0, 0.0];
const DEFAULT_RANDOM: f64 = 0.01;
/// The attributes that give a cube's faces from separate files.
const CUBE_FACE_FILES: [&str; 6] = [
    "fileright",
    "fileleft",
    "fileup",
    "filedown",
    "filefront",
    "fileback",
];

impl<'a> Reader<'a> {
    /// Keeps an `<asset>`'s `<texture>`s by name (MuJoCo's: its file's, unnamed), and the first
    /// skybox.
    pub(super) fn read_textures(&mut self, asset: Node<'a, 'a>) -> Result<()> {
        for texture in self.children(asset)? {
            if !texture.has_tag_name("texture") {
                continue;
            }
            let class = self.declared_class(texture, "class", "main")?;
            let kind = self.attribute(texture, class, "type");
            if kind.as_deref() == Some("skybox") && self.skybox.is_none() {
                self.skybox = Some(texture);
            }
            // named, or by its file's name (a cube's six files give it none)
            if let Some(name) = super::meshes::asset_name(texture) {
                self.textures.insert(name, texture);
            }
        }
        Ok(())
    }

    /// The scene's skybox, if the file has one.
    pub(super) fn skybox_texture(&self) -> Result<Option<Texture>> {
        self.skybox.map(|node| self.texture(node)).transpose()
    }

    /// The texture `material` lays on a geom, if it names one.
    pub(super) fn material_texture(
        &self,
        material: Node<'a, 'a>,
    ) -> Result<Option<TextureMapping>> {
        let class = self.declared_class(material, "class", "main")?;
        let layer = material
            .children()
            .find(|c| c.has_tag_name("layer") && c.attribute("role").is_none_or(|r| r == "rgb"))
            .and_then(|layer| layer.attribute("texture").map(str::to_string));
        let Some(name) = self.attribute(material, class, "texture").or(layer) else {
            return Ok(None);
        };
        let node = *self.textures.get(&name).ok_or_else(|| {
            self.error(
                material,
                format!("attribute 'texture': no <texture name='{name}'> in the <asset>s"),
            )
        })?;
        let repeat = self
            .numbers::<2>(material, class, "texrepeat")?
            .unwrap_or([1.0, 1.0]);
        let uniform = self.flag(material, class, "texuniform")?;
        Ok(Some(TextureMapping {
            texture: self.texture(node)?,
            repeat,
            uniform,
        }))
    }

    /// A `<texture>` element as robodyn keeps it.
    fn texture(&self, node: Node<'a, 'a>) -> Result<Texture> {
        let class = self.declared_class(node, "class", "main")?;
        let kind = match self.attribute(node, class, "type").as_deref() {
            None | Some("2d") => TextureKind::Planar,
            Some("cube") => TextureKind::Cube,
            Some("skybox") => TextureKind::Skybox,
            Some(other) => {
                return Err(self.error(
                    node,
                    format!("attribute 'type': expected 2d, cube or skybox, got '{other}'"),
                ))
            }
        };
        let builtin = self
            .attribute(node, class, "builtin")
            .unwrap_or_else(|| "none".to_string());
        let file = self.attribute(node, class, "file");
        let face_files = CUBE_FACE_FILES
            .iter()
            .any(|a| self.attribute(node, class, a).is_some());
        let image = match (builtin.as_str(), file) {
            ("gradient" | "checker" | "flat", _) => {
                TextureImage::Builtin(self.builtin_texture(node, class, &builtin, kind)?)
            }
            ("none", Some(file)) if kind != TextureKind::Planar => {
                TextureImage::Undrawable(format!(
                    "a {} texture from the file '{file}' is not drawn",
                    kind.as_str()
                ))
            }
            ("none", Some(file)) => self.texture_file(node, class, &file)?,
            ("none", None) if face_files => TextureImage::Undrawable(format!(
                "a {} texture from one file per face is not drawn",
                kind.as_str()
            )),
            ("none", None) => {
                return Err(self.error(
                    node,
                    "expected a 'file' or a 'builtin' pattern, got neither",
                ))
            }
            (other, _) => {
                return Err(self.error(
                    node,
                    format!(
                    "attribute 'builtin': expected none, gradient, checker or flat, got '{other}'"
                ),
                ))
            }
        };
        Ok(Texture {
            name: node
                .attribute("name")
                .map_or_else(|| format!("texture{}", node.range().start), str::to_string),
            kind,
            image,
            element: self.location(node),
        })
    }

    /// A builtin pattern's colours, mark and size; a 2-D one needs a width and a height, a cube's
    /// faces a width, as MuJoCo requires.
    fn builtin_texture(
        &self,
        node: Node<'a, 'a>,
        class: &str,
        pattern: &str,
        kind: TextureKind,
    ) -> Result<BuiltinTexture> {
        let rgb = |name: &str, default: [f64; 3]| -> Result<[f64; 3]> {
            Ok(self.numbers::<3>(node, class, name)?.unwrap_or(default))
        };
        let size = |name: &str| -> Result<usize> {
            let [value] = self.numbers::<1>(node, class, name)?.unwrap_or([0.0]);
            if value.fract() != 0.0 || value < 0.0 {
                return Err(self.error(
                    node,
                    format!("attribute '{name}': expected a whole number of pixels, got {value}"),
                ));
            }
            Ok(value as usize)
        };
        let (width, height) = (size("width")?, size("height")?);
        if width == 0 || (kind == TextureKind::Planar && height == 0) {
            return Err(self.error(
                node,
                "a builtin texture needs a positive 'width' (and 'height' for a 2d one)",
            ));
        }
        let mark = self
            .attribute(node, class, "mark")
            .unwrap_or_else(|| "none".to_string());
        if !matches!(mark.as_str(), "none" | "edge" | "cross" | "random") {
            return Err(self.error(
                node,
                format!("attribute 'mark': expected none, edge, cross or random, got '{mark}'"),
            ));
        }
        Ok(BuiltinTexture {
            pattern: pattern.to_string(),
            rgb1: rgb("rgb1", DEFAULT_RGB1)?,
            rgb2: rgb("rgb2", DEFAULT_RGB2)?,
            mark,
            mark_rgb: rgb("markrgb", DEFAULT_MARK_RGB)?,
            random: self
                .numbers::<1>(node, class, "random")?
                .map_or(DEFAULT_RANDOM, |[x]| x),
            width,
            height: if kind == TextureKind::Planar {
                height
            } else {
                width
            },
        })
    }

    /// A 2-D texture's image file: a PNG found under `<compiler texturedir>` (or `assetdir`),
    /// else why it is not drawn.
    fn texture_file(&self, node: Node<'a, 'a>, class: &str, file: &str) -> Result<TextureImage> {
        let is_png = std::path::Path::new(file)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !is_png {
            return Ok(TextureImage::Undrawable(format!(
                "the texture file '{file}' is not a PNG image"
            )));
        }
        Ok(
            match self.find_asset_file(node, file, self.texture_directory.as_deref(), "texture") {
                Ok(path) => TextureImage::File {
                    path,
                    hflip: self.flag(node, class, "hflip")?,
                    vflip: self.flag(node, class, "vflip")?,
                },
                Err(missing) => TextureImage::Undrawable(missing.to_string()),
            },
        )
    }

    /// A true/false attribute (false when absent).
    pub(super) fn flag(&self, node: Node<'a, 'a>, class: &str, name: &str) -> Result<bool> {
        match self.attribute(node, class, name).as_deref() {
            None | Some("false") => Ok(false),
            Some("true") => Ok(true),
            Some(other) => Err(self.error(
                node,
                format!("attribute '{name}': expected true or false, got '{other}'"),
            )),
        }
    }

    /// Where an asset's file is: relative to `directory` (`<compiler meshdir>`, `texturedir`, or
    /// `assetdir`), itself relative to the main file's folder, else to the folder of the file
    /// holding the element; an error lists every path tried.
    pub(super) fn find_asset_file(
        &self,
        element: Node<'a, 'a>,
        file: &str,
        directory: Option<&str>,
        what: &str,
    ) -> Result<PathBuf> {
        let directory = directory.unwrap_or("");
        let main = self.sources.files[0].folder.clone();
        let own = self.sources.files[self.file_index(element)].folder.clone();
        let mut tried = Vec::new();
        for folder in [main, own].into_iter().flatten() {
            let path = folder.join(directory).join(file);
            if path.is_file() {
                return Ok(path);
            }
            if !tried.contains(&path) {
                tried.push(path);
            }
        }
        if tried.is_empty() {
            return Err(self.error(element, format!("the {what} file '{file}' is resolved against the model's folder: load the model from its file")));
        }
        let places: Vec<String> = tried.iter().map(|p| p.display().to_string()).collect();
        Err(self.error(
            element,
            format!(
                "{what} file '{file}' not found; tried {}",
                places.join(", ")
            ),
        ))
    }
}

//! Height-field geoms: the `<asset><hfield>` they name and its elevations, read as MuJoCo's
//! compiler reads them (MuJoCo's "XML Reference", §asset/hfield):
//! - `elevation`: `nrow × ncol` numbers, written row by row from the field's +y edge down (the
//!   rows are reversed, so that row 0 lies along −y), zeros when left out;
//! - a PNG `file`: one row of pixels per row, the image's top row along +y, each pixel's grey
//!   level (of a colour image, its red channel, as MuJoCo's PNG reader converts it), 8 bits;
//! - any other `file` (or `content_type="image/vnd.mujoco.hfield"`): MuJoCo's binary format,
//!   two 32-bit integers `nrow`, `ncol` and then `nrow × ncol` 32-bit floats, row 0 along −y,
//!   little-endian;
//!
//! found as mesh files are (under `<compiler meshdir>`), and then scaled to [0, 1]
//! ([`HeightField::new`]).

use super::meshes::asset_name;
use super::Reader;
use crate::collision::height_field::HeightField;
use crate::error::Result;
use crate::io::xml::parse_number_list;
use crate::visual::Shape;
use roxmltree::Node;
use std::sync::Arc;

/// `content_type` of a PNG height field.
const PNG: &str = "image/png";
/// `content_type` of MuJoCo's binary format.
const BINARY: &str = "image/vnd.mujoco.hfield";

impl<'a> Reader<'a> {
    /// Remembers every `<hfield>` of an `<asset>` section by name (its `name`, else its file's
    /// stem).
    pub(super) fn read_height_fields(&mut self, asset: Node<'a, 'a>) -> Result<()> {
        for field in self
            .children(asset)?
            .into_iter()
            .filter(|c| c.has_tag_name("hfield"))
        {
            if let Some(name) = asset_name(field) {
                self.height_fields.insert(name, field);
            }
        }
        Ok(())
    }

    /// The height field named `name` (by `geom`'s `hfield`), read once.
    pub(super) fn height_field(&self, geom: Node<'a, 'a>, name: &str) -> Result<Shape> {
        if let Some(field) = self.height_field_cache.borrow().get(name) {
            return Ok(Shape::HeightField {
                field: Arc::clone(field),
            });
        }
        let Some(&asset) = self.height_fields.get(name) else {
            let mut known: Vec<&str> = self.height_fields.keys().map(String::as_str).collect();
            known.sort_unstable();
            return Err(self.error(
                geom,
                format!(
                    "attribute 'hfield': no <hfield> named '{name}' among the assets (known: {})",
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            ));
        };
        let size = self
            .numbers::<4>(asset, "main", "size")?
            .ok_or_else(|| self.error(asset, "attribute 'size': expected four positive numbers (half-sides x and y, top, base), got none"))?;
        let declared = (
            self.integer(asset, "main", "nrow", 0)?,
            self.integer(asset, "main", "ncol", 0)?,
        );
        let (rows, columns, samples) = match asset.attribute("file") {
            Some(file) => {
                if declared != (0, 0) || asset.attribute("elevation").is_some() {
                    self.warnings.borrow_mut().push(format!(
                        "{}: the height field's file '{file}' gives its samples: its nrow, ncol \
                         and elevation are left unread, as MuJoCo leaves them",
                        self.location(asset)
                    ));
                }
                self.height_field_file(asset, file)?
            }
            None => self.inline_elevations(asset, declared)?,
        };
        let field = HeightField::new(size, rows, columns, &samples)
            .map(Arc::new)
            .map_err(|m| self.error(asset, m))?;
        self.height_field_cache
            .borrow_mut()
            .insert(name.to_string(), Arc::clone(&field));
        Ok(Shape::HeightField { field })
    }

    /// `nrow`, `ncol` and the `elevation` numbers (zeros when left out), rows reversed.
    fn inline_elevations(
        &self,
        asset: Node<'a, 'a>,
        (rows, columns): (i64, i64),
    ) -> Result<(usize, usize, Vec<f32>)> {
        let (Ok(rows), Ok(columns)) = (usize::try_from(rows), usize::try_from(columns)) else {
            return Err(self.error(asset, format!("attributes 'nrow', 'ncol': expected positive numbers of rows and columns, got {rows} and {columns}")));
        };
        if rows == 0 || columns == 0 {
            return Err(self.error(
                asset,
                "a height field needs a file, or nrow and ncol (and elevation): none given",
            ));
        }
        let written = match asset.attribute("elevation") {
            Some(text) => parse_number_list(text, "elevation").map_err(|m| self.error(asset, m))?,
            None => vec![0.0; rows * columns],
        };
        if written.len() != rows * columns {
            return Err(self.error(
                asset,
                format!(
                    "attribute 'elevation': expected nrow x ncol = {} numbers, got {}",
                    rows * columns,
                    written.len()
                ),
            ));
        }
        // the first written row is the last row, along +y
        let samples = written
            .chunks(columns)
            .rev()
            .flatten()
            .map(|&h| h as f32)
            .collect();
        Ok((rows, columns, samples))
    }

    /// The samples of a height-field file: PNG or MuJoCo's binary format.
    fn height_field_file(
        &self,
        asset: Node<'a, 'a>,
        file: &str,
    ) -> Result<(usize, usize, Vec<f32>)> {
        let content = match asset.attribute("content_type") {
            Some(kind) if kind == PNG || kind == BINARY => kind,
            Some(other) => {
                return Err(self.error(
                    asset,
                    format!(
                        "attribute 'content_type': expected '{PNG}' or '{BINARY}', got '{other}'"
                    ),
                ))
            }
            None if file.to_ascii_lowercase().ends_with(".png") => PNG,
            None => BINARY,
        };
        let path =
            self.find_asset_file(asset, file, self.mesh_directory.as_deref(), "height field")?;
        let bytes = std::fs::read(&path).map_err(|e| {
            self.error(
                asset,
                format!(
                    "cannot read the height field file '{}': {e}",
                    path.display()
                ),
            )
        })?;
        let read = if content == PNG {
            png_samples(&bytes)
        } else {
            binary_samples(&bytes)
        };
        read.map_err(|m| {
            self.error(
                asset,
                format!("the height field file '{}': {m}", path.display()),
            )
        })
    }
}

/// A PNG's rows (the image's top row last) of grey levels: the first channel of each pixel at
/// 8 bits (palettes expanded, 16 bits cut to their high byte).
fn png_samples(bytes: &[u8]) -> std::result::Result<(usize, usize, Vec<f32>), String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("not a PNG image ({e})"))?;
    let length = reader
        .output_buffer_size()
        .ok_or("the image is too large")?;
    let mut pixels = vec![0; length];
    let info = reader
        .next_frame(&mut pixels)
        .map_err(|e| format!("a broken PNG image ({e})"))?;
    let (rows, columns) = (info.height as usize, info.width as usize);
    let channels = info.color_type.samples();
    let samples = (0..rows)
        .rev()
        .flat_map(|r| {
            let line = &pixels[r * info.line_size..];
            (0..columns).map(move |c| f32::from(line[c * channels]))
        })
        .collect();
    Ok((rows, columns, samples))
}

/// MuJoCo's binary height field: `nrow`, `ncol` (int32), then `nrow × ncol` float32.
fn binary_samples(bytes: &[u8]) -> std::result::Result<(usize, usize, Vec<f32>), String> {
    // little-endian 32-bit words, four bytes each
    let words = || bytes.chunks_exact(4).map(|w| [w[0], w[1], w[2], w[3]]);
    if bytes.len() < 8 {
        return Err(format!(
            "expected a header of two 32-bit integers, got {} bytes",
            bytes.len()
        ));
    }
    let mut header = words().map(i32::from_le_bytes);
    let (rows, columns) = (header.next().unwrap_or(0), header.next().unwrap_or(0));
    if rows < 1 || columns < 1 {
        return Err(format!(
            "expected positive nrow and ncol in the header, got {rows} and {columns}"
        ));
    }
    let (rows, columns) = (rows as usize, columns as usize);
    let expected = 8 + 4 * rows * columns;
    if bytes.len() != expected {
        return Err(format!(
            "expected {expected} bytes for {rows} x {columns} elevations, got {}",
            bytes.len()
        ));
    }
    let samples = words().skip(2).map(f32::from_le_bytes).collect();
    Ok((rows, columns, samples))
}

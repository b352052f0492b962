//! The report's drawings as PNG images (BCF snapshots): the SVG rendered with resvg.
//!
//! No fonts are loaded, so labels are left out and the image is the same on every machine;
//! the shapes and their verdict colours are what a snapshot shows (the labels are in the
//! HTML report and in the BCF topic's text).

use resvg::{tiny_skia, usvg};

/// Largest side of a rendered image (px): a drawing larger than this is scaled down.
const MAX_SIDE: f32 = 2048.0;

#[derive(Debug, thiserror::Error)]
pub enum PngError {
    #[error("the drawing is not valid SVG: {0}")]
    Svg(#[from] usvg::Error),
    #[error("the drawing has no area to render")]
    Empty,
    #[error("cannot encode the PNG: {0}")]
    Encode(String),
}

/// `svg` rendered on a white background at its own size (scaled down to MAX_SIDE at most).
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>, PngError> {
    let tree = usvg::Tree::from_str(svg, &usvg::Options::default())?;
    let size = tree.size();
    let scale = (MAX_SIDE / size.width().max(size.height())).min(1.0);
    let (w, h) = (
        (size.width() * scale).ceil() as u32,
        (size.height() * scale).ceil() as u32,
    );
    let mut pixmap = tiny_skia::Pixmap::new(w, h).ok_or(PngError::Empty)?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|e| PngError::Encode(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_a_red_square_where_the_svg_puts_it() {
        let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20">
            <rect x="20" y="0" width="20" height="20" fill="#ff0000"/></svg>"##;
        let png = svg_to_png(svg).unwrap();
        let image = tiny_skia::Pixmap::decode_png(&png).unwrap();
        assert_eq!((image.width(), image.height()), (40, 20));
        let at = |x: u32, y: u32| image.pixel(x, y).unwrap();
        let left = at(5, 10);
        let right = at(30, 10);
        assert_eq!((left.red(), left.green(), left.blue()), (255, 255, 255));
        assert_eq!((right.red(), right.green(), right.blue()), (255, 0, 0));
    }

    #[test]
    fn bad_svg_is_an_error() {
        assert!(svg_to_png("<svg").is_err());
    }
}

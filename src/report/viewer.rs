//! The 3D view of a wall's run inside the report's pages: the wall's scene (the bytes of its
//! `scene*.glb`) deflated (zlib) and base64-encoded into a `script type="application/octet-stream"`
//! element, and `viewer.js` (plain WebGL, written for this report) once per page to draw every
//! view on it: the animated run, play and pause, a time slider, an orbit camera, and a click on
//! a piece showing its verdict and root cause beside the canvas.
//!
//! Nothing from the model is written into a script: the scene is base64 (it cannot close its
//! element), the markup around it goes through maud, and the script reads names only from the
//! scene and sets them as text.

use flate2::Compression;
use flate2::write::ZlibEncoder;
use maud::{Markup, PreEscaped, html};
use std::io::Write;

/// The viewer's script, included once in a page that shows a view.
pub const SCRIPT: &str = include_str!("viewer.js");

/// A scene as a page embeds it: zlib-deflated, then base64 (standard alphabet, padded).
pub fn embed(glb: &[u8]) -> String {
    let mut z = ZlibEncoder::new(Vec::with_capacity(glb.len() / 2), Compression::default());
    // Writing into memory cannot fail.
    let _ = z.write_all(glb);
    base64(&z.finish().unwrap_or_default())
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// One wall's view: the canvas with a panel for the picked piece, the controls, a message for
/// a browser without script or WebGL (the canvas and controls stay hidden there), and the
/// scene (`embedded`, from [`embed`]; `scene` names the file beside the page).
pub fn view(embedded: &str, scene: &str) -> Markup {
    html! {
        figure class="viewer" {
            div class="viewer-stage" hidden {
                canvas width="640" height="360" aria-label="3D view of the run" {}
                div class="viewer-info" aria-live="polite" {}
            }
            div class="viewer-controls" hidden {
                button type="button" class="play" { "Play" }
                input type="range" class="time" min="0" max="1" step="any" value="1" aria-label="time";
                output class="clock" {}
                label { "speed "
                    select class="speed" {
                        option value="1" { "1×" }
                        option value="5" { "5×" }
                        option value="10" selected { "10×" }
                        option value="30" { "30×" }
                    }
                }
            }
            p class="viewer-message" {
                "The 3D view of the run needs JavaScript and WebGL; "
                a href=(scene) { (scene) } " holds the same scene for any glTF viewer."
            }
            script type="application/octet-stream" class="viewer-scene" { (PreEscaped(embedded)) }
        }
    }
}

/// The script that starts every view on the page (at the end of its body).
pub fn script() -> Markup {
    html! { script { (PreEscaped(SCRIPT)) } }
}

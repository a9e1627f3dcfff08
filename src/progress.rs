//! The terminal progress bar of one render: the renderer reports finished tiles through a
//! hook ([`crate::render::Progress`]) and knows nothing of terminals.

use crate::render::Progress;
use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Arc;

/// A bar on stderr counting tiles, or None when `show` is false.
pub fn tiles(show: bool) -> Option<Progress> {
    if !show {
        return None;
    }
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} rendering [{bar:30}] {pos}/{len} tiles, {elapsed} (eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    Some(Progress(Arc::new(move |done, total| {
        bar.set_length(total);
        bar.set_position(done);
        if done == total {
            bar.finish_and_clear();
        }
    })))
}

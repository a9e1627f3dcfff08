//! The interactive HTML report (issue 49, in progress): the embedded image data is here
//! ([`data`]); the page and its browser test come next.

pub mod data;
pub mod page;

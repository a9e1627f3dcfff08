//! The one error type of the scene readers.
//!
//! Every message names the file, the line when known, the element and what was expected, so a
//! user can fix a scene without reading the loader's source.

use std::fmt;
use std::path::PathBuf;

/// An error in a scene file, with the file, line and element it concerns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneError {
    /// The XML file being read (as given by the user, not canonicalised, so messages match
    /// what they typed).
    pub file: PathBuf,
    /// 1-based line in `file`, when the error can be tied to one.
    pub line: Option<u32>,
    /// The offending element's opening tag as written, e.g. `<float name="fov" value="abc">`.
    pub element: Option<String>,
    /// What is wrong and what was expected.
    pub message: String,
}

impl SceneError {
    /// An error about `file` as a whole (no line or element).
    pub fn new(file: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        SceneError {
            file: file.into(),
            line: None,
            element: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(element) = &self.element {
            write!(f, ": {element}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_file_line_element_and_message() {
        let e = SceneError {
            file: "scenes/cbox.xml".into(),
            line: Some(14),
            element: Some(r#"<float name="fov" value="abc">"#.into()),
            message: r#"expected a number, found "abc""#.into(),
        };
        assert_eq!(
            e.to_string(),
            r#"scenes/cbox.xml:14: <float name="fov" value="abc">: expected a number, found "abc""#
        );
        let bare = SceneError::new("a.xml", "oops");
        assert_eq!(bare.to_string(), "a.xml: oops");
    }
}

//! The bug gallery: wrong variants of the sampling code, each one classic mistake from the
//! study (`shared/REFERENCE.md` section 1), run through the real checks — the chi-square
//! engine, one-sample t-tests against Lambert's closed form (`analytic::polygon_irradiance`)
//! and against the furnace, and Welch tests of unbiasedness across strategies. The correct
//! code runs through the same checks as a control and must pass all of them.
//!
//! Compiled only for tests. `every_bug_is_caught` asserts that each bug fails at least one
//! check; the report `reports/bug-gallery.md` is regenerated with
//! `cargo test --release --lib gallery -- --ignored`.

mod estimate;
mod lights;
mod receiver;
mod table;

use receiver::Receiver;

/// One mistake (or none) in the sampling code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bug {
    None,
    PmfNotDivided,
    SharedRandom,
    TrianglesUniform,
    MissingCos,
    BackFacingPdf,
    MisMixedDirections,
    CosineWithUniformPdf,
    WiWoSwapped,
}

impl Bug {
    pub fn describe(self) -> &'static str {
        match self {
            Bug::None => "none (control)",
            Bug::PmfNotDivided => "emitter-choice pmf not divided out",
            Bug::SharedRandom => "one random number for emitter, triangle and point",
            Bug::TrianglesUniform => "triangles picked uniformly, not by area",
            Bug::MissingCos => "cos(theta_light) missing from the area-to-solid-angle Jacobian",
            Bug::BackFacingPdf => "back-facing light still given a pdf",
            Bug::MisMixedDirections => "MIS weights from pdfs of different directions",
            Bug::CosineWithUniformPdf => "cosine-hemisphere sampler paired with the uniform pdf",
            Bug::WiWoSwapped => "wi and wo swapped in the BSDF pdf",
        }
    }
}

pub const DIFFUSE: Receiver = Receiver::Diffuse { albedo: 0.5 };
/// Nori's microfacet: its pdf is not symmetric in (wi, wo).
pub const MICROFACET: Receiver = Receiver::Microfacet {
    alpha: 0.3,
    kd: 0.4,
};

/// The gallery's rows: every bug on the receiver that can show it, plus controls.
pub fn rows() -> Vec<(Bug, Receiver)> {
    vec![
        (Bug::None, DIFFUSE),
        (Bug::None, MICROFACET),
        (Bug::PmfNotDivided, DIFFUSE),
        (Bug::SharedRandom, DIFFUSE),
        (Bug::TrianglesUniform, DIFFUSE),
        (Bug::MissingCos, DIFFUSE),
        (Bug::BackFacingPdf, DIFFUSE),
        (Bug::MisMixedDirections, DIFFUSE),
        (Bug::CosineWithUniformPdf, DIFFUSE),
        (Bug::WiWoSwapped, MICROFACET),
    ]
}

#[cfg(test)]
mod tests {
    use super::table::{markdown, run_table};
    use super::*;

    #[test]
    fn every_bug_is_caught_and_the_correct_code_is_not() {
        let t = run_table();
        for row in &t.rows {
            let caught: Vec<&str> = row
                .cells
                .iter()
                .zip(table::COLUMNS)
                .filter(|(c, _)| c.caught(t.alpha))
                .map(|(_, col)| col.key)
                .collect();
            if row.bug == Bug::None {
                assert!(
                    caught.is_empty(),
                    "control {:?} rejected by {caught:?}",
                    row.receiver
                );
            } else {
                assert!(!caught.is_empty(), "{:?} escaped every check", row.bug);
            }
        }
    }

    /// Writes `reports/bug-gallery.md` (same seeds as the test above, so the same numbers).
    #[test]
    #[ignore]
    fn regenerate_bug_gallery() {
        let md = markdown(&run_table());
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("reports/bug-gallery.md");
        crate::output::write_atomic(&path, |tmp| {
            std::fs::write(tmp, &md).map_err(|e| e.to_string())
        })
        .unwrap();
        eprintln!("{md}");
    }
}

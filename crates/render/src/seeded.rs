//! Seeded bugs: mistakes of the kind that leave an image plausible, each wrong in one corner
//! of the configuration space, for the two-run test's gallery (`tests/e2e/seeded_bugs.rs`,
//! `reports/seeded-bugs/`), which must find each against the correct build.
//!
//! Compiled in only with the `seeded-bugs` feature, which the harness enables for its own
//! tests (a dev-dependency feature; `cargo build` and `reproduce` never have it): without
//! it `active` is the constant false and the sites fold away. With it, the environment
//! variable `DIRECTLAB_SEEDED_BUG` names the bug of the whole process, read once; an
//! unknown name panics with the list. Cached references are keyed by `tag()` too, so a
//! buggy run never reads or writes a correct run's cache.

/// One seeded mistake.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeededBug {
    /// One side of a surface: light sampling treats an area light as emitting from both
    /// sides (`emitter::area::facing` tests `cos != 0`, not `cos > 0`); BSDF sampling still
    /// sees the back side black.
    BackFacingLight,
    /// One range of angles: a guard against dividing by a tiny cosine clamps cos(theta) at
    /// the light to at least 0.1 in the area-to-solid-angle density; exact above 84 degrees
    /// from the light's normal, too small a density (too bright) at grazing emission.
    GrazingCosClamp,
    /// One kind of shape: a point on a sphere light drawn uniformly in polar angle rather
    /// than in cos(theta), while its density stays 1 / area (too many points near the poles).
    SpherePolarUniform,
    /// One material: smooth plastic's diffuse lobe leaves through the Fresnel term of the
    /// incident direction, (1 - F(wi))^2 instead of (1 - F(wi)) (1 - F(wo)).
    PlasticExitFresnel,
}

/// Every seeded bug with its name (`DIRECTLAB_SEEDED_BUG`), what it is wrong in, and what
/// the mistake is.
pub const ALL: &[(SeededBug, &str, &str, &str)] = &[
    (
        SeededBug::BackFacingLight,
        "back-facing-light",
        "one side of a surface",
        "light sampling takes an area light's back side as emitting (cos != 0, not cos > 0)",
    ),
    (
        SeededBug::GrazingCosClamp,
        "grazing-cos-clamp",
        "one range of angles",
        "cos(theta) at the light clamped to at least 0.1 in the light's solid-angle density",
    ),
    (
        SeededBug::SpherePolarUniform,
        "sphere-polar-uniform",
        "one kind of shape",
        "sphere lights' points drawn uniformly in polar angle, density still 1 / area",
    ),
    (
        SeededBug::PlasticExitFresnel,
        "plastic-exit-fresnel",
        "one material",
        "smooth plastic's diffuse lobe exits through F(wi), not F(wo)",
    ),
];

/// The environment variable that names the process's seeded bug.
pub const VAR: &str = "DIRECTLAB_SEEDED_BUG";

/// Whether `bug` is the process's seeded bug.
#[inline(always)]
pub fn active(bug: SeededBug) -> bool {
    #[cfg(feature = "seeded-bugs")]
    {
        current() == Some(bug)
    }
    #[cfg(not(feature = "seeded-bugs"))]
    {
        let _ = bug;
        false
    }
}

/// The process's seeded bug, if any.
#[cfg(feature = "seeded-bugs")]
pub fn current() -> Option<SeededBug> {
    static BUG: std::sync::OnceLock<Option<SeededBug>> = std::sync::OnceLock::new();
    *BUG.get_or_init(|| {
        let name = std::env::var(VAR).ok().filter(|v| !v.is_empty())?;
        match ALL.iter().find(|(_, n, _, _)| *n == name) {
            Some(&(b, ..)) => Some(b),
            None => panic!(
                "{VAR}={name}: no such seeded bug (known: {})",
                ALL.iter().map(|b| b.1).collect::<Vec<_>>().join(", ")
            ),
        }
    })
}

/// The process's seeded bug, if any (none: this build has no seeded bugs).
#[cfg(not(feature = "seeded-bugs"))]
pub fn current() -> Option<SeededBug> {
    None
}

/// The active bug's name, or "" (a field of the reference cache key).
pub fn tag() -> &'static str {
    current().map_or("", |b| ALL.iter().find(|e| e.0 == b).map_or("", |e| e.1))
}

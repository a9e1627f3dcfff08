//! Loader tests of BSDF elements: parameters, defaults, references and `twosided`, and the
//! materials the other loader tests compare against.

use super::tests::{m3, m3_err, shape_bsdf};
use crate::bsdf::{
    BsdfKind, Conductor, Dielectric, Diffuse, Material, NoriMicrofacet, Plastic, RoughConductor,
    RoughPlastic,
};
use crate::sampling::microfacet::{Microfacet, MicrofacetDistribution};
use glam::Vec3;

pub(super) use crate::scene::fixtures::one_sided as one;

pub(super) fn two(m: Material) -> Material {
    Material {
        two_sided: true,
        ..m
    }
}

pub(super) fn diffuse(reflectance: Vec3) -> Material {
    one(BsdfKind::Diffuse(Diffuse { reflectance }))
}

fn conductor(eta: Vec3, k: Vec3, specular_reflectance: Vec3) -> Material {
    one(BsdfKind::Conductor(Conductor {
        eta,
        k,
        specular_reflectance,
    }))
}

fn rough(
    d: MicrofacetDistribution,
    alpha_u: f32,
    alpha_v: f32,
    sample_visible: bool,
    eta: Vec3,
    k: Vec3,
    specular_reflectance: Vec3,
) -> Material {
    one(BsdfKind::RoughConductor(RoughConductor {
        mf: Microfacet::new(d, alpha_u, alpha_v),
        sample_visible,
        eta,
        k,
        specular_reflectance,
    }))
}

pub(super) fn dielectric(int_ior: f32, ext_ior: f32) -> Material {
    one(BsdfKind::Dielectric(Dielectric {
        eta: int_ior / ext_ior,
    }))
}

pub(super) fn nori(alpha: f32, int_ior: f32, ext_ior: f32, kd: Vec3) -> Material {
    one(BsdfKind::NoriMicrofacet(NoriMicrofacet::new(
        alpha, int_ior, ext_ior, kd,
    )))
}

#[test]
fn refs_and_twosided() {
    let s = m3(r#"
        <shape type="rectangle"><ref id="later"/></shape>
        <shape type="rectangle"><ref name="bsdf" id="red"/></shape>
        <shape type="rectangle"><bsdf type="twosided"><ref id="red"/></bsdf></shape>
        <shape type="rectangle"/>
        <bsdf type="diffuse" id="red"><rgb name="reflectance" value="0.63, 0.065, 0.05"/></bsdf>
        <bsdf type="twosided" id="later"><bsdf type="diffuse"/></bsdf>"#);
    let red = diffuse(Vec3::new(0.63, 0.065, 0.05));
    let grey = diffuse(Vec3::splat(0.5));
    assert_eq!(s.shapes[0].bsdf, two(grey.clone()));
    assert_eq!(s.shapes[1].bsdf, red);
    assert_eq!(s.shapes[2].bsdf, two(red));
    assert_eq!(s.shapes[3].bsdf, grey);

    let e = m3_err(r#"<shape type="rectangle"><ref id="nope"/></shape>"#);
    assert!(
        e.contains("test.xml:2: <ref id=\"nope\">: no top-level <bsdf> has id 'nope'"),
        "{e}"
    );
    let e = m3_err(r#"<bsdf type="twosided" id="a"><ref id="a"/></bsdf>"#);
    assert!(e.contains("refers to itself"), "{e}");
}

/// The material of a rectangle holding `inner`.
fn b(inner: &str) -> Material {
    let s = m3(&format!(r#"<shape type="rectangle">{inner}</shape>"#));
    shape_bsdf(&s).clone()
}

#[test]
fn bsdf_parameters_and_defaults() {
    assert_eq!(b(r#"<bsdf type="diffuse"/>"#), diffuse(Vec3::splat(0.5)));
    assert_eq!(
        b(r#"<bsdf type="diffuse"><float name="reflectance" value="0.2"/></bsdf>"#),
        diffuse(Vec3::splat(0.2))
    );
    assert_eq!(
        b(r#"<bsdf type="conductor"/>"#),
        conductor(Vec3::ZERO, Vec3::ONE, Vec3::ONE)
    );
    match b(r#"<bsdf type="conductor"><string name="material" value="Au"/></bsdf>"#) {
        Material {
            kind: BsdfKind::Conductor(Conductor { eta, k, .. }),
            ..
        } => {
            assert!((eta.x - 0.143119).abs() < 1e-5 && (k.x - 3.98316).abs() < 1e-4);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        b(
            r#"<bsdf type="conductor"><rgb name="eta" value="0.2"/><rgb name="k" value="3"/>
             <rgb name="specular_reflectance" value="0.9"/></bsdf>"#
        ),
        conductor(Vec3::splat(0.2), Vec3::splat(3.0), Vec3::splat(0.9))
    );
    assert_eq!(
        b(r#"<bsdf type="roughconductor"/>"#),
        rough(
            MicrofacetDistribution::Beckmann,
            0.1,
            0.1,
            true,
            Vec3::ZERO,
            Vec3::ONE,
            Vec3::ONE
        )
    );
    match b(
        r#"<bsdf type="roughconductor"><string name="distribution" value="ggx"/>
          <float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.3"/>
          <boolean name="sample_visible" value="false"/><string name="material" value="Cu"/></bsdf>"#,
    ) {
        Material {
            kind: BsdfKind::RoughConductor(rc),
            ..
        } => {
            assert_eq!(rc.mf.distribution, MicrofacetDistribution::Ggx);
            let (au, av) = (rc.mf.alpha_u, rc.mf.alpha_v);
            assert_eq!((au, av, rc.sample_visible), (0.05, 0.3, false));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        b(r#"<bsdf type="dielectric"/>"#),
        dielectric(1.5046, 1.000277)
    );
    assert_eq!(
        b(
            r#"<bsdf type="dielectric"><string name="int_ior" value="water"/>
             <float name="ext_ior" value="1.1"/></bsdf>"#
        ),
        dielectric(1.333, 1.1)
    );
    assert_eq!(
        b(
            r#"<bsdf type="dielectric"><string name="int_ior" value="diamond"/>
             <string name="ext_ior" value="vacuum"/></bsdf>"#
        ),
        dielectric(2.419, 1.0)
    );
}

#[test]
fn coated_bsdf_parameters_and_defaults() {
    match b(
        r#"<bsdf type="roughplastic"><string name="distribution" value="ggx"/>
             <float name="alpha" value="0.3"/><boolean name="sample_visible" value="false"/>
             <float name="int_ior" value="1.6"/><boolean name="nonlinear" value="true"/></bsdf>"#,
    ) {
        Material {
            kind: BsdfKind::RoughPlastic(r),
            ..
        } => {
            let mf = Microfacet::new(MicrofacetDistribution::Ggx, 0.3, 0.3);
            let want =
                RoughPlastic::new(mf, false, 1.6 / 1.000277, Vec3::splat(0.5), Vec3::ONE, true);
            assert_eq!(r, want);
        }
        other => panic!("{other:?}"),
    }
    let one_sided = |p: Plastic| one(BsdfKind::Plastic(p));
    assert_eq!(
        b(r#"<bsdf type="plastic"/>"#),
        one_sided(Plastic::new(
            1.49 / 1.000277,
            Vec3::splat(0.5),
            Vec3::ONE,
            false
        ))
    );
    assert_eq!(
        b(
            r#"<bsdf type="plastic"><string name="int_ior" value="bk7"/><float name="ext_ior" value="1.1"/>
             <rgb name="diffuse_reflectance" value="0.1, 0.2, 0.3"/>
             <float name="specular_reflectance" value="0.7"/><boolean name="nonlinear" value="true"/></bsdf>"#
        ),
        one_sided(Plastic::new(
            1.5046 / 1.1,
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::splat(0.7),
            true
        ))
    );
}

#[test]
fn bsdf_parameter_errors() {
    let e =
        m3_err(r#"<bsdf type="dielectric" id="g"><string name="int_ior" value="glassy"/></bsdf>"#);
    assert!(e.contains("unknown IOR name \"glassy\""), "{e}");
    let e = m3_err(
        r#"<bsdf type="roughconductor" id="r"><float name="alpha" value="0.1"/><float name="alpha_u" value="0.1"/></bsdf>"#,
    );
    assert!(e.contains("not both"), "{e}");
    let e = m3_err(
        r#"<bsdf type="conductor" id="c"><string name="material" value="Unobtainium"/></bsdf>"#,
    );
    assert!(e.contains("not supported yet"), "{e}");
    for (eta, k) in [("-0.2", "3"), ("0.2", "1e7"), ("0.2", "1, 2, -3")] {
        let e = m3_err(&format!(
            r#"<bsdf type="roughconductor" id="c"><rgb name="eta" value="{eta}"/><rgb name="k" value="{k}"/></bsdf>"#
        ));
        assert!(
            e.contains("test.xml:2: <bsdf type=\"roughconductor\" id=\"c\">: conductor ")
                && e.contains("must lie in [0, 1e6] in every channel"),
            "{e}"
        );
    }
    let e = m3_err(r#"<bsdf type="roughdielectric" id="p"/>"#);
    assert!(
        e.contains(
            "test.xml:2: <bsdf type=\"roughdielectric\" id=\"p\">: bsdf 'roughdielectric' is not supported yet"
        ),
        "{e}"
    );
    let e =
        m3_err(r#"<bsdf type="diffuse" id="d"><texture type="bitmap" name="reflectance"/></bsdf>"#);
    assert!(e.contains("texture 'bitmap' is not supported yet"), "{e}");
}

/// A plastic whose Mitsuba fits make it reflect more than it receives is read, with a
/// warning that says how much and why; the default plastic reads without one.
#[test]
fn plastic_that_creates_energy_is_named_in_a_warning() {
    let hot = m3(
        r#"<shape type="rectangle"><bsdf type="plastic"><float name="int_ior" value="3"/>
         <rgb name="diffuse_reflectance" value="1"/></bsdf></shape>"#,
    );
    assert!(
        hot.warnings.iter().any(|w| w.contains("test.xml:")
            && w.contains("reflects 1.18")
            && w.contains("plastic")),
        "{:?}",
        hot.warnings
    );
    let fine = m3(r#"<shape type="rectangle"><bsdf type="plastic"/></shape>"#);
    assert!(fine.warnings.is_empty(), "{:?}", fine.warnings);
}

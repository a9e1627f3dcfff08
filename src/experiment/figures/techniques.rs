//! Per-technique images at the comparison spp (issue 70, `directlab_render::aov`): for each
//! strategy, the light-sampled and the BSDF-sampled parts of its seed-0 estimate and the
//! mean MIS weight of each technique's samples that carry light. They show where each
//! technique does the work (Veach's weight maps), which error numbers cannot.

use super::{panel_of, Figure, PANEL};
use crate::experiment::runner::Outcome;
use crate::plot::panels::{write_figure, Panel};
use directlab_render::aov::render_aov;
use directlab_render::film::Image;

/// A weight image (values in [0, 1], one per pixel) as grey levels.
fn weight_panel(img: &Image, title: &str) -> Panel {
    let rgb = img
        .data
        .iter()
        .flat_map(|p| [(p[0].clamp(0.0, 1.0) * 255.0 + 0.5) as u8; 3])
        .collect();
    Panel::new(title, img.width, img.height, rgb)
}

/// `techniques.png`: a row per strategy (light part, BSDF part, their weights), rendered
/// here at the comparison spp with seed 0 and the strategy's sampler.
pub(super) fn techniques(o: &Outcome) -> Result<Option<Figure>, String> {
    if o.methods.is_empty() {
        return Ok(None);
    }
    let spp = o.exp.equal_spp();
    let case = &o.exp.cases[0];
    let scene = directlab_render::scene::open_with(&case.scene, &case.defines, case.integrator)?;
    let exposure = o.exp.exp.figures.exposure.unwrap_or(1.0);
    let mut rows = Vec::new();
    for ((_, name), method) in o.strategies.iter().zip(&o.methods) {
        let film = (scene.camera.width, scene.camera.height);
        let settings = method.settings(spp, 0, None, film)?;
        let aov = render_aov(&scene, method.strategy, &settings);
        rows.push(vec![
            panel_of(&aov.light, exposure, &format!("{name}: light part")).fit(PANEL),
            panel_of(&aov.bsdf, exposure, "BSDF part").fit(PANEL),
            weight_panel(&aov.weight_light, "mean weight, light samples").fit(PANEL),
            weight_panel(&aov.weight_bsdf, "mean weight, BSDF samples").fit(PANEL),
        ]);
    }
    let file = "techniques.png";
    write_figure(
        &o.dir.join(file),
        &format!("Per technique at {spp} spp (seed 0)"),
        &rows,
    )?;
    Ok(Some(Figure {
        file: file.into(),
        caption: format!(
            "Each strategy's estimate at {spp} spp split by technique: the part from light \
             samples and the part from BSDF samples (they add up to the image, less the \
             emission seen directly), and the mean MIS weight of each technique's samples \
             that carry light (black: 0, or no such sample in the pixel; white: 1; a pure \
             strategy weights its own samples 1, and the other technique's fallback samples, \
             for the paths only they reach, 1)."
        ),
    }))
}

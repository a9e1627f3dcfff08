//! Scene loading as the element count grows: an XML file of `n` small rectangle emitters
//! (each with a transform and an area emitter, six elements) is written, then read into a
//! scene description and built (meshes, emitter tables, BVH), each step timed.

use super::{BenchArgs, Row};
use crate::scene::{load_scene, Scene};
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// Writes the scene of `n` emitters over a floor.
fn write_scene(path: &Path, n: usize) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        w,
        "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"45\"/>\
         <transform name=\"to_world\"><lookat origin=\"0,0,-30\" target=\"0,0,0\" up=\"0,1,0\"/>\
         </transform><film type=\"hdrfilm\"><integer name=\"width\" value=\"32\"/>\
         <integer name=\"height\" value=\"32\"/></film></sensor>\n<shape type=\"rectangle\">\
         <transform name=\"to_world\"><scale value=\"100\"/><translate z=\"5\"/></transform></shape>"
    )?;
    let side = (n as f64).sqrt().ceil() as usize;
    for k in 0..n {
        let (x, y) = ((k % side) as f32 * 0.05, (k / side) as f32 * 0.05);
        writeln!(
            w,
            "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"0.02\"/>\
             <translate x=\"{x}\" y=\"{y}\" z=\"1\"/></transform><emitter type=\"area\">\
             <rgb name=\"radiance\" value=\"1\"/></emitter></shape>"
        )?;
    }
    writeln!(w, "</scene>")?;
    w.flush()
}

/// The load sweep: prints it and adds its rows (seconds to read the XML into a description,
/// and to build the scene from it).
pub(super) fn section(a: &BenchArgs, rows: &mut Vec<Row>) -> Result<(), String> {
    println!("scene loading as the emitter count grows (one thread for parsing; best of 1):");
    println!(
        "  {:>9} {:>10} {:>10} {:>10}",
        "emitters", "MB of XML", "load s", "build s"
    );
    let path =
        std::env::temp_dir().join(format!("directlab-bench-load-{}.xml", std::process::id()));
    let counts = [1_000usize, 10_000, 100_000, 1_000_000];
    for &n in counts.iter().filter(|&&n| n <= a.max_load_emitters) {
        write_scene(&path, n).map_err(|e| format!("{}: {e}", path.display()))?;
        let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
        let t = Instant::now();
        let desc = load_scene(&path, &[]);
        let load = t.elapsed().as_secs_f64();
        let desc = desc.map_err(|e| e.to_string())?;
        let t = Instant::now();
        let scene = Scene::build(desc).map_err(|e| e.to_string())?;
        let build = t.elapsed().as_secs_f64();
        assert_eq!(scene.emitters.len(), n);
        drop(scene);
        println!(
            "  {n:>9} {:>10.1} {load:>10.2} {build:>10.2}",
            bytes as f64 / 1e6
        );
        for (section, value) in [("load_xml", load), ("load_build", build)] {
            rows.push(Row {
                section,
                scene: format!("{n} rectangle emitters"),
                strategy: String::new(),
                threads: 1,
                n: n as u64,
                value,
                unit: "s",
            });
        }
    }
    let _ = std::fs::remove_file(&path);
    Ok(())
}

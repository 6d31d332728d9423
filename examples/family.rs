//! Write a body of the randomised families (`blmesh::surface::family`) for `blmesh mesh`.
//!
//! `cargo run --release --example family -- FAMILY SEED OUT.stl|OUT.mesh [FINENESS]`, FAMILY one
//! of wing-plate, fin-cylinder, post-plate, grooves, slots, steps, bumps. An STL file holds one
//! solid per patch (the patch names survive reading it back); `.mesh` is Medit's format.

use std::io::Write;

use blmesh::surface::family::{family_body_at, Family};
use blmesh::surface::Surface;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let names: Vec<&str> = Family::ALL.iter().map(|f| f.name()).collect();
    let usage =
        format!("usage: family FAMILY SEED OUT.stl|OUT.mesh [FINENESS], FAMILY one of {}", names.join(", "));
    if args.len() < 3 {
        return Err(usage.into());
    }
    let family = Family::from_name(&args[0]).ok_or(usage)?;
    let seed: u64 = args[1].parse()?;
    let fineness: f64 = args.get(3).map_or(Ok(1.0), |f| f.parse())?;
    let surface = family_body_at(family, seed, fineness);
    let path = std::path::Path::new(&args[2]);
    blmesh::io::write_atomic(path, |w| {
        if path.extension().is_some_and(|e| e == "mesh") {
            blmesh::io::medit::write_surface(w, &surface, false)
        } else {
            write_stl(w, &surface)
        }
    })?;
    eprintln!(
        "{} seed {seed}: {} triangles, {} points",
        family.name(),
        surface.triangles.len(),
        surface.points.len()
    );
    Ok(())
}

/// ASCII STL, one solid per patch.
fn write_stl(w: &mut dyn Write, s: &Surface) -> std::io::Result<()> {
    for (patch, name) in s.patch_names.iter().enumerate() {
        writeln!(w, "solid {name}")?;
        for t in (0..s.triangles.len()).filter(|&t| s.triangle_patch[t] as usize == patch) {
            let n = s.triangle_normal(t);
            writeln!(w, "facet normal {:e} {:e} {:e}\n outer loop", n.x, n.y, n.z)?;
            for p in s.triangle_points(t) {
                writeln!(w, "  vertex {:.17e} {:.17e} {:.17e}", p.x, p.y, p.z)?;
            }
            writeln!(w, " endloop\nendfacet")?;
        }
        writeln!(w, "endsolid {name}")?;
    }
    Ok(())
}

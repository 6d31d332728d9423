//! Developer tool: a picture of a planar cut through a mesh, around a point.
//!
//! `cargo run --release --example cut -- MESH.vtu OUT.png X Y Z NX NY NZ HALF_WIDTH [quality]`
//! cuts MESH by the plane through (X, Y, Z) normal to (NX, NY, NZ) and draws the square of side
//! 2 HALF_WIDTH around that point, cells coloured by kind (or by scaled Jacobian).

use blmesh::geometry::DVec3;
use blmesh::io::read_volume_mesh;
use blmesh::picture::{cut_picture, write_png, Colouring, CutPlane, View};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 9 {
        return Err("usage: cut MESH OUT.png X Y Z NX NY NZ HALF_WIDTH [quality]".into());
    }
    let number = |i: usize| args[i].parse::<f64>();
    let origin = DVec3::new(number(2)?, number(3)?, number(4)?);
    let normal = DVec3::new(number(5)?, number(6)?, number(7)?);
    let colouring =
        if args.get(9).is_some_and(|a| a == "quality") { Colouring::Quality } else { Colouring::Kind };
    let mesh = read_volume_mesh(args[0].as_ref())?;
    let picture = cut_picture(
        &mesh,
        &CutPlane { origin, normal },
        &View::around(origin, number(8)?),
        colouring,
        1200,
        1200,
    );
    write_png(&picture, args[1].as_ref())?;
    Ok(())
}

//! Helpers on spade's constrained Delaunay triangulations, shared by the stages that
//! triangulate planar regions.

use spade::handles::FixedUndirectedEdgeHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// Faces of the triangulation inside the region the edges picked by `bounds` enclose (an odd
/// number of them crossed on the way from the outer face), by face index. Decided by topology
/// alone, so three nearly collinear boundary points never make a face both in and out.
pub fn inside_faces(
    cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>,
    bounds: impl Fn(FixedUndirectedEdgeHandle) -> bool,
) -> Vec<bool> {
    let mut parity: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let outer = cdt.outer_face();
    parity[outer.fix().index()] = Some(false);
    let mut stack = vec![(outer.fix(), false)];
    while let Some((face, inside)) = stack.pop() {
        // Each edge of the face, with the face across it.
        let edges: Vec<_> = match cdt.face(face).as_inner() {
            Some(inner) => inner.adjacent_edges().iter().map(|e| (*e, e.rev().face().fix())).collect(),
            None => cdt
                .convex_hull()
                .map(|e| {
                    let across = if e.face().is_outer() { e.rev().face() } else { e.face() };
                    (e, across.fix())
                })
                .collect(),
        };
        for (e, across) in edges {
            if parity[across.index()].is_some() {
                continue;
            }
            let flips = bounds(e.as_undirected().fix());
            parity[across.index()] = Some(inside != flips);
            stack.push((across, inside != flips));
        }
    }
    parity.into_iter().map(|p| p.unwrap_or(false)).collect()
}

//! The checker's report: what [`super::check`] found, serialisable to JSON and printable.

use std::collections::BTreeMap;
use std::fmt;

use serde::Serialize;

use crate::geometry::DVec3;
use crate::mesh::CellKind;

/// How many examples of each kind of problem a report keeps.
pub const EXAMPLES: usize = 10;

/// Largest relative difference between the cell volumes and the enclosed volume of a valid mesh.
pub const VOLUME_TOLERANCE: f64 = 1e-9;

/// One value per cell kind.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PerKind<T> {
    pub tetrahedron: T,
    pub pyramid: T,
    pub prism: T,
    pub hexahedron: T,
}

impl<T> PerKind<T> {
    pub fn get(&self, kind: CellKind) -> &T {
        match kind {
            CellKind::Tetrahedron => &self.tetrahedron,
            CellKind::Pyramid => &self.pyramid,
            CellKind::Prism => &self.prism,
            CellKind::Hexahedron => &self.hexahedron,
        }
    }

    pub fn get_mut(&mut self, kind: CellKind) -> &mut T {
        match kind {
            CellKind::Tetrahedron => &mut self.tetrahedron,
            CellKind::Pyramid => &mut self.pyramid,
            CellKind::Prism => &mut self.prism,
            CellKind::Hexahedron => &mut self.hexahedron,
        }
    }
}

/// A cell: its kind and its index in that kind's block.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct CellRef {
    pub kind: CellKind,
    pub index: usize,
}

/// A boundary face of the mesh: a triangle or quad of `VolumeMesh::boundary`, by index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct BoundaryRef {
    pub quad: bool,
    pub index: usize,
}

fn to_array(p: &[DVec3]) -> Vec<[f64; 3]> {
    p.iter().map(|q| q.to_array()).collect()
}

/// An invalid cell with its nodes and their coordinates.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InvalidCell {
    pub cell: CellRef,
    pub nodes: Vec<u32>,
    pub points: Vec<[f64; 3]>,
    pub problem: String,
}

impl InvalidCell {
    pub fn new(cell: CellRef, nodes: &[u32], points: &[DVec3], problem: String) -> Self {
        InvalidCell { cell, nodes: nodes.to_vec(), points: to_array(points), problem }
    }
}

/// Validity of the cells (exact orientation of both decompositions).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Validity {
    pub invalid_cells: usize,
    /// Cells with a corner tetrahedron that is not positive.
    pub inverted_corners: usize,
    /// Cells with a tetrahedron of the standard (centroid) decomposition that is not positive.
    pub nonpositive_decomposition: usize,
    pub nodes_out_of_range: usize,
    pub examples: Vec<InvalidCell>,
}

impl Validity {
    /// Add the counts of `other` and keep the first examples.
    pub fn append(&mut self, other: Validity) {
        self.invalid_cells += other.invalid_cells;
        self.inverted_corners += other.inverted_corners;
        self.nonpositive_decomposition += other.nonpositive_decomposition;
        self.nodes_out_of_range += other.nodes_out_of_range;
        let room = EXAMPLES.saturating_sub(self.examples.len());
        self.examples.extend(other.examples.into_iter().take(room));
    }
}

/// What can be wrong with a face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaceProblem {
    NonManifoldFace,
    DoubledFace,
    TwistedQuad,
    NonMatchingQuadSplit,
    Hole,
    InvertedBoundaryFace,
    BoundaryFaceNotCovered,
    DuplicateBoundaryFace,
}

impl FaceProblem {
    pub fn describe(self) -> &'static str {
        match self {
            FaceProblem::NonManifoldFace => "face shared by three or more cells",
            FaceProblem::DoubledFace => {
                "face shared by two cells with the same orientation (doubled or overlapping cells)"
            }
            FaceProblem::TwistedQuad => "quad face whose two cells order its vertices differently",
            FaceProblem::NonMatchingQuadSplit => {
                "non-matching quad split: a quad face meets two triangle faces of a neighbour"
            }
            FaceProblem::Hole => "hole: a face of one cell only that is no boundary face",
            FaceProblem::InvertedBoundaryFace => "boundary face oriented into the domain",
            FaceProblem::BoundaryFaceNotCovered => "boundary face not covered by a free cell face",
            FaceProblem::DuplicateBoundaryFace => "boundary face listed twice",
        }
    }
}

/// One face problem, with the cells and boundary faces involved.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaceIssue {
    pub problem: FaceProblem,
    pub nodes: Vec<u32>,
    /// Mean of the face's points (absent when a node index is out of range).
    pub centre: Option<[f64; 3]>,
    pub cells: Vec<CellRef>,
    pub boundary_faces: Vec<BoundaryRef>,
}

/// Conformity of the faces.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Conformity {
    /// Faces shared by two cells.
    pub interior_faces: usize,
    /// Faces of one cell only (the mesh's boundary seen from its cells).
    pub free_triangles: usize,
    pub free_quads: usize,
    /// The mesh lists no boundary faces: its free faces are taken as its boundary.
    pub free_faces_taken_as_boundary: bool,
    pub errors: usize,
    pub by_problem: BTreeMap<FaceProblem, usize>,
    pub examples: Vec<FaceIssue>,
}

impl Conformity {
    pub fn record(&mut self, issue: FaceIssue) {
        self.errors += 1;
        let count = self.by_problem.entry(issue.problem).or_insert(0);
        *count += 1;
        if *count <= EXAMPLES {
            self.examples.push(issue);
        }
    }
}

/// Sum of the cell volumes against the volume enclosed by the free faces.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct VolumeCheck {
    pub cells: f64,
    pub enclosed: f64,
    pub relative_difference: f64,
}

/// Min, max, mean and histogram of a quality measure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct QualityStats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    /// `[0]`: values <= 0; `[1 + k]`: values in [k/10, (k+1)/10) (the last bin takes 1 and above).
    pub histogram: [usize; 11],
    #[serde(skip)]
    sum: f64,
    #[serde(skip)]
    count: usize,
}

impl Default for QualityStats {
    fn default() -> Self {
        QualityStats {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            mean: 0.0,
            histogram: [0; 11],
            sum: 0.0,
            count: 0,
        }
    }
}

impl QualityStats {
    pub fn add(&mut self, q: f64) {
        let bin = if q > 0.0 { 1 + ((q * 10.0) as usize).min(9) } else { 0 };
        self.histogram[bin] += 1;
        self.min = self.min.min(q);
        self.max = self.max.max(q);
        self.sum += q;
        self.count += 1;
        self.mean = self.sum / self.count as f64;
    }

    pub fn merge(&mut self, other: &QualityStats) {
        for (h, o) in self.histogram.iter_mut().zip(other.histogram) {
            *h += o;
        }
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
        self.sum += other.sum;
        self.count += other.count;
        self.mean = if self.count > 0 { self.sum / self.count as f64 } else { 0.0 };
    }
}

/// Quality of the cells of one kind.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KindQuality {
    pub cells: usize,
    /// Scaled Jacobian (definitions of `shared/bench/measure.py`).
    pub scaled_jacobian: QualityStats,
    /// Smallest and largest interior angle between two faces sharing an edge, in degrees.
    pub dihedral_deg: [f64; 2],
}

impl Default for KindQuality {
    fn default() -> Self {
        KindQuality {
            cells: 0,
            scaled_jacobian: QualityStats::default(),
            dihedral_deg: [f64::INFINITY, f64::NEG_INFINITY],
        }
    }
}

impl KindQuality {
    pub fn add(&mut self, scaled_jacobian: f64, (lo, hi): (f64, f64)) {
        self.cells += 1;
        self.scaled_jacobian.add(scaled_jacobian);
        self.dihedral_deg = [self.dihedral_deg[0].min(lo), self.dihedral_deg[1].max(hi)];
    }

    pub fn merge(&mut self, other: &KindQuality) {
        self.cells += other.cells;
        self.scaled_jacobian.merge(&other.scaled_jacobian);
        self.dihedral_deg = [
            self.dihedral_deg[0].min(other.dihedral_deg[0]),
            self.dihedral_deg[1].max(other.dihedral_deg[1]),
        ];
    }
}

/// Boundary faces of one patch.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PatchCount {
    pub name: String,
    pub triangles: usize,
    pub quads: usize,
}

/// Everything [`super::check`] found.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CheckReport {
    pub points: usize,
    pub unused_points: usize,
    pub cells: PerKind<usize>,
    pub patches: Vec<PatchCount>,
    /// Inconsistent data (block lengths, zone or patch indices out of range).
    pub structure_errors: Vec<String>,
    pub warnings: Vec<String>,
    pub validity: Validity,
    pub conformity: Conformity,
    pub volume: VolumeCheck,
    /// The boundary crossing itself: cells folded over each other.
    pub overlap: super::overlap::Overlap,
    /// Quality of the cells whose nodes are in range (invalid cells included).
    pub quality: PerKind<KindQuality>,
    /// Finite-volume measures (what OpenFOAM's checkMesh reports).
    pub fv: super::FvReport,
}

impl CheckReport {
    pub fn cell_count(&self) -> usize {
        CellKind::ALL.iter().map(|&k| *self.cells.get(k)).sum()
    }

    /// The volume identity holds: cells add up to the enclosed volume.
    pub fn volume_identity_holds(&self) -> bool {
        self.volume.relative_difference < VOLUME_TOLERANCE
    }

    /// At least one cell, no invalid cell, no conformity or structure error, and the volume
    /// identity holds.
    pub fn is_valid(&self) -> bool {
        self.cell_count() > 0
            && self.structure_errors.is_empty()
            && self.validity.invalid_cells == 0
            && self.conformity.errors == 0
            && self.overlap.intersecting_pairs == 0
            && self.volume_identity_holds()
    }
}

fn point(p: &[f64; 3]) -> String {
    format!("({:.6}, {:.6}, {:.6})", p[0], p[1], p[2])
}

impl fmt::Display for CheckReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_counts(self, f)?;
        for e in &self.structure_errors {
            writeln!(f, "error: {e}")?;
        }
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        write_validity(&self.validity, f)?;
        write_conformity(&self.conformity, f)?;
        let v = &self.volume;
        let verdict = if self.volume_identity_holds() { "ok" } else { "MISMATCH" };
        writeln!(
            f,
            "volume: cells {:.12e}, enclosed by the free faces {:.12e}, relative difference {:.1e} \
             ({verdict})",
            v.cells, v.enclosed, v.relative_difference
        )?;
        let o = &self.overlap;
        if o.intersecting_pairs == 0 {
            writeln!(f, "overlap: none (the boundary does not cross itself)")?;
        } else {
            writeln!(
                f,
                "overlap: the boundary crosses itself at {} pairs of faces: cells fold over each other",
                o.intersecting_pairs
            )?;
            for [a, b] in o.examples.iter().take(EXAMPLES) {
                writeln!(f, "  faces at {} and {}", point(a), point(b))?;
            }
        }
        write_quality(&self.quality, f)?;
        write!(f, "{}", self.fv)?;
        writeln!(f, "{}", if self.is_valid() { "VALID" } else { "INVALID" })
    }
}

fn write_counts(r: &CheckReport, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    let kinds: Vec<String> =
        CellKind::ALL.iter().map(|&k| format!("{} {}", r.cells.get(k), k.name())).collect();
    writeln!(
        f,
        "points: {} ({} unused); cells: {} ({})",
        r.points,
        r.unused_points,
        r.cell_count(),
        kinds.join(", ")
    )?;
    let patches: Vec<String> =
        r.patches.iter().map(|p| format!("{} ({} tri, {} quad)", p.name, p.triangles, p.quads)).collect();
    writeln!(f, "patches: {}", if patches.is_empty() { "none".to_string() } else { patches.join(", ") })
}

fn write_validity(v: &Validity, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    if v.invalid_cells == 0 {
        return writeln!(f, "validity: ok (every tetrahedron of both decompositions positive)");
    }
    writeln!(
        f,
        "validity: {} invalid cells ({} with an inverted corner, {} with a non-positive decomposition, \
         {} with nodes out of range)",
        v.invalid_cells, v.inverted_corners, v.nonpositive_decomposition, v.nodes_out_of_range
    )?;
    for e in &v.examples {
        let pts: Vec<String> = e.points.iter().take(4).map(point).collect();
        writeln!(
            f,
            "  {} {} nodes {:?}: {} at {}",
            e.cell.kind.name(),
            e.cell.index,
            e.nodes,
            e.problem,
            pts.join(" ")
        )?;
    }
    Ok(())
}

fn write_conformity(c: &Conformity, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    let taken = if c.free_faces_taken_as_boundary { ", taken as the boundary" } else { "" };
    writeln!(
        f,
        "conformity: {} interior faces, {} free triangles and {} free quads{taken}; {} errors",
        c.interior_faces, c.free_triangles, c.free_quads, c.errors
    )?;
    for (problem, count) in &c.by_problem {
        writeln!(f, "  {count} x {}", problem.describe())?;
    }
    for e in c.examples.iter().take(EXAMPLES) {
        let cells: Vec<String> = e.cells.iter().map(|c| format!("{} {}", c.kind.name(), c.index)).collect();
        let at = e.centre.as_ref().map(point).unwrap_or_else(|| "?".into());
        writeln!(f, "  {:?}: face {:?} at {at}, cells [{}]", e.problem, e.nodes, cells.join(", "))?;
    }
    Ok(())
}

fn write_quality(q: &PerKind<KindQuality>, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    for kind in CellKind::ALL {
        let k = q.get(kind);
        if k.cells == 0 {
            continue;
        }
        let s = &k.scaled_jacobian;
        writeln!(
            f,
            "quality {}: scaled Jacobian min {:.4} mean {:.4} max {:.4}, {} <= 0; dihedral {:.2}..{:.2} deg",
            kind.name(),
            s.min,
            s.mean,
            s.max,
            s.histogram[0],
            k.dihedral_deg[0],
            k.dihedral_deg[1]
        )?;
    }
    Ok(())
}

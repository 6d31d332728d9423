//! The finite-volume part of the checker's report ([`FvReport`]) and how the per-face and
//! per-cell measures of [`super::fv`] add up to it.

use std::collections::BTreeMap;
use std::fmt;

use serde::Serialize;

use super::fv::{CellGeometry, FaceMeasures};
use crate::mesh::{Across, CellKind};

/// How many worst faces of each measure a report locates.
pub const WORST_FACES: usize = 5;

/// Non-orthogonality (degrees) above which checkMesh calls a face severely non-orthogonal.
pub const SEVERE_NON_ORTHOGONALITY: f64 = 70.0;

/// Non-orthogonality (degrees) above which a face is counted as one a solver's non-orthogonal
/// correction can hardly mend (its correction term grows as `tan` of the angle: 11 at 85).
pub const SOLVER_LIMIT_NON_ORTHOGONALITY: f64 = 85.0;

/// Skewness above which checkMesh calls an interior face highly skewed.
pub const HIGH_SKEWNESS: f64 = 4.0;

/// Face flatness below which checkMesh calls a face warped.
pub const LOW_FLATNESS: f64 = 0.8;

/// A face located for the reader: its centre, the kinds of its cells, and a measure's value.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LocatedFace {
    pub value: f64,
    pub centre: [f64; 3],
    pub owner: CellKind,
    /// The neighbour cell's kind; none for a boundary face.
    pub neighbour: Option<CellKind>,
    /// The boundary face's patch index.
    pub patch: Option<u32>,
}

/// Non-orthogonality of the interior faces between two kinds of cells.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PairNonOrthogonality {
    pub faces: usize,
    pub max: f64,
    pub mean: f64,
    pub above_70: usize,
    #[serde(skip)]
    sum: f64,
}

impl PairNonOrthogonality {
    fn add(&mut self, value: f64) {
        self.faces += 1;
        self.max = self.max.max(value);
        self.sum += value;
        self.above_70 += usize::from(value > SEVERE_NON_ORTHOGONALITY);
    }

    fn merge(&mut self, other: &PairNonOrthogonality) {
        self.faces += other.faces;
        self.max = self.max.max(other.max);
        self.sum += other.sum;
        self.above_70 += other.above_70;
    }
}

/// What [`super::fv`] measured: OpenFOAM checkMesh's figures. Non-orthogonality statistics and
/// the skewness threshold count interior faces; the maxima of skewness cover every face.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FvReport {
    pub faces: usize,
    pub interior_faces: usize,
    pub boundary_faces: usize,
    /// Degrees, over the interior faces.
    pub non_orthogonality_max: f64,
    pub non_orthogonality_mean: f64,
    pub faces_above_70: usize,
    pub faces_above_80: usize,
    /// Interior faces above [`SOLVER_LIMIT_NON_ORTHOGONALITY`].
    pub faces_above_85: usize,
    /// Interior faces a solver cannot use: the centre line meets the face at 90 degrees or more.
    pub faces_at_or_above_90: usize,
    /// Degrees, over the boundary faces (owner centre to face centre).
    pub boundary_non_orthogonality_max: f64,
    pub skewness_max: f64,
    pub faces_skewness_above_4: usize,
    /// Faces whose pyramid with apex at the owner centre is not positive, or at the neighbour
    /// centre not negative.
    pub wrong_face_pyramids: usize,
    pub cell_volume_min: f64,
    pub cell_openness_max: f64,
    pub aspect_ratio_max: f64,
    pub face_flatness_min: f64,
    pub faces_flatness_below_0_8: usize,
    /// Interior faces by the kinds of their two cells ("prism-pyramid", ...).
    pub non_orthogonality_by_kinds: BTreeMap<String, PairNonOrthogonality>,
    pub worst_non_orthogonality: Vec<LocatedFace>,
    pub worst_skewness: Vec<LocatedFace>,
    /// A few faces with a wrong pyramid (value: the face's non-orthogonality).
    pub wrong_pyramid_examples: Vec<LocatedFace>,
}

impl Default for FvReport {
    fn default() -> Self {
        FvReport {
            faces: 0,
            interior_faces: 0,
            boundary_faces: 0,
            non_orthogonality_max: 0.0,
            non_orthogonality_mean: 0.0,
            faces_above_70: 0,
            faces_above_80: 0,
            faces_above_85: 0,
            faces_at_or_above_90: 0,
            boundary_non_orthogonality_max: 0.0,
            skewness_max: 0.0,
            faces_skewness_above_4: 0,
            wrong_face_pyramids: 0,
            cell_volume_min: 0.0,
            cell_openness_max: 0.0,
            aspect_ratio_max: 0.0,
            face_flatness_min: 1.0,
            faces_flatness_below_0_8: 0,
            non_orthogonality_by_kinds: BTreeMap::new(),
            worst_non_orthogonality: Vec::new(),
            worst_skewness: Vec::new(),
            wrong_pyramid_examples: Vec::new(),
        }
    }
}

impl FvReport {
    /// Why a finite-volume solver would refuse the mesh, if it would.
    pub fn rejection(&self) -> Option<String> {
        let mut why = Vec::new();
        if self.wrong_face_pyramids > 0 {
            why.push(format!("{} faces with a wrong face pyramid", self.wrong_face_pyramids));
        }
        if self.faces_at_or_above_90 > 0 {
            why.push(format!("{} faces at 90 degrees non-orthogonality or more", self.faces_at_or_above_90));
        }
        (!why.is_empty()).then(|| why.join(", "))
    }
}

/// Where a face is: what [`LocatedFace`] needs besides the value.
#[derive(Clone, Copy, Debug)]
pub struct FaceSides {
    pub owner: CellKind,
    pub neighbour: Option<CellKind>,
    pub across: Across,
}

/// A running sum of face and cell measures, merged across threads.
#[derive(Clone, Debug, Default)]
pub struct FvTally {
    report: FvReport,
    non_orthogonality_sum: f64,
    pairs: [[PairNonOrthogonality; 4]; 4],
    cells: usize,
}

/// Insert `face` among the `WORST_FACES` largest values of `list` (kept in decreasing order).
fn keep_worst(list: &mut Vec<LocatedFace>, face: LocatedFace) {
    if face.value.is_nan() || list.len() == WORST_FACES && list.last().is_some_and(|w| w.value >= face.value)
    {
        return;
    }
    let at = list.partition_point(|w| w.value >= face.value);
    list.insert(at, face);
    list.truncate(WORST_FACES);
}

fn located(m: &FaceMeasures, sides: &FaceSides, value: f64) -> LocatedFace {
    let patch = match sides.across {
        Across::Patch(p) => Some(p),
        _ => None,
    };
    LocatedFace { value, centre: m.centre.to_array(), owner: sides.owner, neighbour: sides.neighbour, patch }
}

impl FvTally {
    pub fn add_face(mut self, m: &FaceMeasures, sides: &FaceSides) -> Self {
        let r = &mut self.report;
        r.faces += 1;
        let angle = m.non_orthogonality;
        if let Some(neighbour) = sides.neighbour {
            r.interior_faces += 1;
            r.non_orthogonality_max = r.non_orthogonality_max.max(angle);
            self.non_orthogonality_sum += angle;
            r.faces_above_70 += usize::from(angle > SEVERE_NON_ORTHOGONALITY);
            r.faces_above_80 += usize::from(angle > 80.0);
            r.faces_above_85 += usize::from(angle > SOLVER_LIMIT_NON_ORTHOGONALITY);
            r.faces_at_or_above_90 += usize::from(angle >= 90.0);
            r.faces_skewness_above_4 += usize::from(m.skewness > HIGH_SKEWNESS);
            let (a, b) = (sides.owner.min(neighbour), sides.owner.max(neighbour));
            self.pairs[a as usize][b as usize].add(angle);
            keep_worst(&mut r.worst_non_orthogonality, located(m, sides, angle));
        } else {
            r.boundary_faces += 1;
            r.boundary_non_orthogonality_max = r.boundary_non_orthogonality_max.max(angle);
        }
        r.skewness_max = r.skewness_max.max(m.skewness);
        keep_worst(&mut r.worst_skewness, located(m, sides, m.skewness));
        if m.wrong_pyramid {
            r.wrong_face_pyramids += 1;
            if r.wrong_pyramid_examples.len() < WORST_FACES {
                r.wrong_pyramid_examples.push(located(m, sides, angle));
            }
        }
        r.face_flatness_min = r.face_flatness_min.min(m.flatness);
        r.faces_flatness_below_0_8 += usize::from(m.flatness < LOW_FLATNESS);
        self
    }

    pub fn add_cell(mut self, c: &CellGeometry) -> Self {
        let r = &mut self.report;
        r.cell_volume_min = if self.cells == 0 { c.volume } else { r.cell_volume_min.min(c.volume) };
        r.cell_openness_max = r.cell_openness_max.max(c.openness);
        r.aspect_ratio_max = r.aspect_ratio_max.max(c.aspect_ratio);
        self.cells += 1;
        self
    }

    pub fn merge(mut self, other: FvTally) -> Self {
        let (r, o) = (&mut self.report, other.report);
        r.faces += o.faces;
        r.interior_faces += o.interior_faces;
        r.boundary_faces += o.boundary_faces;
        r.non_orthogonality_max = r.non_orthogonality_max.max(o.non_orthogonality_max);
        r.faces_above_70 += o.faces_above_70;
        r.faces_above_80 += o.faces_above_80;
        r.faces_above_85 += o.faces_above_85;
        r.faces_at_or_above_90 += o.faces_at_or_above_90;
        r.boundary_non_orthogonality_max =
            r.boundary_non_orthogonality_max.max(o.boundary_non_orthogonality_max);
        r.skewness_max = r.skewness_max.max(o.skewness_max);
        r.faces_skewness_above_4 += o.faces_skewness_above_4;
        r.wrong_face_pyramids += o.wrong_face_pyramids;
        r.cell_volume_min = match (self.cells, other.cells) {
            (0, _) => o.cell_volume_min,
            (_, 0) => r.cell_volume_min,
            _ => r.cell_volume_min.min(o.cell_volume_min),
        };
        r.cell_openness_max = r.cell_openness_max.max(o.cell_openness_max);
        r.aspect_ratio_max = r.aspect_ratio_max.max(o.aspect_ratio_max);
        r.face_flatness_min = r.face_flatness_min.min(o.face_flatness_min);
        r.faces_flatness_below_0_8 += o.faces_flatness_below_0_8;
        for face in o.worst_non_orthogonality {
            keep_worst(&mut r.worst_non_orthogonality, face);
        }
        for face in o.worst_skewness {
            keep_worst(&mut r.worst_skewness, face);
        }
        let room = WORST_FACES.saturating_sub(r.wrong_pyramid_examples.len());
        r.wrong_pyramid_examples.extend(o.wrong_pyramid_examples.into_iter().take(room));
        self.non_orthogonality_sum += other.non_orthogonality_sum;
        for (mine, theirs) in self.pairs.iter_mut().flatten().zip(other.pairs.iter().flatten()) {
            mine.merge(theirs);
        }
        self.cells += other.cells;
        self
    }

    pub fn finish(self) -> FvReport {
        let mut r = self.report;
        if r.interior_faces > 0 {
            r.non_orthogonality_mean = self.non_orthogonality_sum / r.interior_faces as f64;
        }
        for (a, row) in self.pairs.into_iter().enumerate() {
            for (b, mut pair) in row.into_iter().enumerate().filter(|(_, p)| p.faces > 0) {
                pair.mean = pair.sum / pair.faces as f64;
                let name = format!("{}-{}", CellKind::ALL[a].name(), CellKind::ALL[b].name());
                r.non_orthogonality_by_kinds.insert(name, pair);
            }
        }
        r
    }
}

fn at(face: &LocatedFace) -> String {
    let [x, y, z] = face.centre;
    let across = match (face.neighbour, face.patch) {
        (Some(k), _) => k.name().to_string(),
        (None, Some(p)) => format!("patch {p}"),
        (None, None) => "nothing".to_string(),
    };
    format!("{:.3} at ({x:.6}, {y:.6}, {z:.6}) between {} and {across}", face.value, face.owner.name())
}

impl fmt::Display for FvReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "fv: {} faces ({} interior); non-orthogonality max {:.2} mean {:.2} deg, {} above 70, {} above \
             80, {} above 85, {} at 90 or more; skewness max {:.3}, {} above 4; {} wrong face pyramids",
            self.faces,
            self.interior_faces,
            self.non_orthogonality_max,
            self.non_orthogonality_mean,
            self.faces_above_70,
            self.faces_above_80,
            self.faces_above_85,
            self.faces_at_or_above_90,
            self.skewness_max,
            self.faces_skewness_above_4,
            self.wrong_face_pyramids
        )?;
        writeln!(
            f,
            "  boundary non-orthogonality max {:.2} deg; cell openness max {:.1e}; aspect ratio max {:.1}; \
             face flatness min {:.3} ({} below 0.8); smallest cell volume {:.3e}",
            self.boundary_non_orthogonality_max,
            self.cell_openness_max,
            self.aspect_ratio_max,
            self.face_flatness_min,
            self.faces_flatness_below_0_8,
            self.cell_volume_min
        )?;
        for (pair, p) in &self.non_orthogonality_by_kinds {
            writeln!(
                f,
                "  {pair}: {} faces, non-orthogonality max {:.2} mean {:.2}, {} above 70",
                p.faces, p.max, p.mean, p.above_70
            )?;
        }
        for face in self.worst_non_orthogonality.iter().take(3) {
            writeln!(f, "  worst non-orthogonality {}", at(face))?;
        }
        for face in self.worst_skewness.iter().take(3) {
            writeln!(f, "  worst skewness {}", at(face))?;
        }
        for face in &self.wrong_pyramid_examples {
            writeln!(f, "  wrong face pyramid: non-orthogonality {}", at(face))?;
        }
        if let Some(why) = self.rejection() {
            writeln!(f, "  a finite-volume solver would reject this mesh: {why}")?;
        }
        Ok(())
    }
}

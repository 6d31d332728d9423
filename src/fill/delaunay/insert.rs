//! Bowyer–Watson insertion: locate by a visibility walk, grow the cavity, join its boundary
//! to the new point.

use super::{Cell, Delaunay, FACES, FREE, INFINITE};
use crate::geometry::predicates::{insphere, insphere_tie, orient3d, Sign};
use crate::geometry::DVec3;

/// Reusable buffers of one insertion.
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    /// Per tetrahedron slot, the verdict of the insertion under way, if it tested it (one
    /// byte a slot, cleared after each insertion: the slots it tests are few, and a small
    /// array stays in the cache).
    verdicts: Vec<Option<Verdict>>,
    /// The slots with a verdict.
    tested: Vec<u32>,
    stack: Vec<u32>,
    cavity: Vec<u32>,
    boundary: Vec<BoundaryFace>,
    created: Vec<u32>,
    edges: EdgeTable,
}

impl Scratch {
    /// Start an insertion among `slots` tetrahedron slots.
    fn begin(&mut self, slots: usize) {
        self.verdicts.resize(slots, None);
        self.stack.clear();
        self.cavity.clear();
        self.boundary.clear();
        self.created.clear();
    }

    /// Record the verdict on `t`; one inside joins the cavity, to grow from.
    fn judge(&mut self, t: u32, verdict: Verdict) {
        if self.verdicts[t as usize].replace(verdict).is_none() {
            self.tested.push(t);
        }
        if verdict.inside() {
            self.cavity.push(t);
            self.stack.push(t);
        }
    }

    fn inside(&self, t: u32) -> bool {
        self.verdicts[t as usize].is_some_and(Verdict::inside)
    }

    /// Forget the verdicts.
    fn end(&mut self) {
        for &t in &self.tested {
            self.verdicts[t as usize] = None;
        }
        self.tested.clear();
    }
}

/// Whether a tetrahedron is in the cavity of the point being inserted, and whether the exact
/// predicate said so (a strict verdict) or the perturbation (a tie broken).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Verdict {
    Inside,
    InsideByTie,
    Outside,
    OutsideByTie,
}

impl Verdict {
    fn inside(self) -> bool {
        matches!(self, Verdict::Inside | Verdict::InsideByTie)
    }

    /// The verdict of a predicate's sign (`Positive`: inside), strict or not.
    fn of_sign(sign: Sign, strict: bool) -> Verdict {
        match (sign == Sign::Positive, strict) {
            (true, true) => Verdict::Inside,
            (true, false) => Verdict::InsideByTie,
            (false, true) => Verdict::Outside,
            (false, false) => Verdict::OutsideByTie,
        }
    }
}

/// A face of the cavity's boundary and the tetrahedron it will carry.
#[derive(Clone, Copy, Debug)]
struct BoundaryFace {
    /// The cavity tetrahedron's vertices with the new point in place of the vertex opposite
    /// the face.
    cell: [u32; 4],
    /// Where the new point is in `cell`.
    apex: usize,
    /// The tetrahedron across the face, outside the cavity, and the index of the face in it.
    outside: u32,
    back: usize,
}

/// The position of the infinite vertex in `cell`, if it has it.
fn infinite_at(cell: [u32; 4]) -> Option<usize> {
    cell.iter().position(|&v| v == INFINITE)
}

/// The two local vertices after `apex` on face `face` (which contains it), in the face's
/// orientation: the face reads `(apex, x, y)`.
fn after_apex(apex: usize, face: usize) -> (usize, usize) {
    let [f0, f1, f2] = FACES[face];
    if f0 == apex {
        (f1, f2)
    } else if f1 == apex {
        (f2, f0)
    } else {
        (f0, f1)
    }
}

impl Delaunay {
    /// A live tetrahedron whose closure contains `p`, or an infinite one with `p` strictly
    /// outside its hull face. The walk leaves a finite tetrahedron through a face that has `p`
    /// strictly on its far side, the faces tried from a random one on; on the Delaunay
    /// tetrahedralisation such a walk ends. (A walk longer than there are tetrahedra falls back
    /// on a search of them all.)
    pub(super) fn locate(&mut self, p: DVec3) -> u32 {
        let mut t = self.hint;
        let mut came_from = FREE;
        for _ in 0..self.cells.len() {
            let cell = self.cells[t as usize].vertices;
            if let Some(k) = infinite_at(cell) {
                let [a, b, c] = FACES[k].map(|i| self.points[cell[i] as usize]);
                if orient3d(a, b, c, p) == Sign::Positive {
                    return t;
                }
                came_from = t;
                t = self.cells[t as usize].neighbours[k];
                continue;
            }
            let corners = cell.map(|v| self.points[v as usize]);
            let first = (self.rng.next_u64() >> 62) as usize;
            let exit = (0..4).map(|j| (first + j) & 3).find(|&i| {
                let n = self.cells[t as usize].neighbours[i];
                let [a, b, c] = FACES[i].map(|l| corners[l]);
                n != came_from && orient3d(a, b, c, p) == Sign::Negative
            });
            match exit {
                Some(i) => {
                    came_from = t;
                    t = self.cells[t as usize].neighbours[i];
                }
                None => return t,
            }
        }
        self.locate_by_search(p)
    }

    /// [`Delaunay::locate`] over every tetrahedron.
    fn locate_by_search(&self, p: DVec3) -> u32 {
        let contains = |t: &usize| {
            let cell = self.cells[*t].vertices;
            if cell[0] == FREE {
                return false;
            }
            let side = |i: usize| {
                let [a, b, c] = FACES[i].map(|l| self.points[cell[l] as usize]);
                orient3d(a, b, c, p)
            };
            match infinite_at(cell) {
                Some(k) => side(k) == Sign::Positive,
                None => (0..4).all(|i| side(i) != Sign::Negative),
            }
        };
        (0..self.cells.len()).find(contains).expect("the tetrahedra cover space") as u32
    }

    /// The finite vertex of tetrahedron `t` at `p`, if any.
    pub(super) fn vertex_at(&self, t: u32, p: DVec3) -> Option<u32> {
        let cell = self.cells[t as usize].vertices;
        cell.into_iter().find(|&v| v != INFINITE && self.points[v as usize] == p)
    }

    /// Whether `p` is in the cavity of tetrahedron `t` (the module's predicate rules).
    fn verdict(&self, t: u32, p: DVec3) -> Verdict {
        let cell = self.cells[t as usize].vertices;
        match infinite_at(cell) {
            None => {
                let [a, b, c, d] = cell.map(|v| self.points[v as usize]);
                match insphere(a, b, c, d, p) {
                    Sign::Zero => Verdict::of_sign(insphere_tie(a, b, c, d, p), false),
                    sign => Verdict::of_sign(sign, true),
                }
            }
            Some(k) => {
                let [a, b, c] = FACES[k].map(|i| self.points[cell[i] as usize]);
                match orient3d(a, b, c, p) {
                    Sign::Zero => match self.verdict(self.cells[t as usize].neighbours[k], p) {
                        Verdict::Inside | Verdict::InsideByTie => Verdict::InsideByTie,
                        Verdict::Outside | Verdict::OutsideByTie => Verdict::OutsideByTie,
                    },
                    sign => Verdict::of_sign(sign, true),
                }
            }
        }
    }

    /// Whether the tetrahedron that joins `p` to face `i` of tetrahedron `t` is positive
    /// (or infinite: the hull around it stays convex when the finite ones are positive).
    fn joins_positive(&self, t: u32, i: usize, p: DVec3) -> bool {
        let cell = self.cells[t as usize].vertices;
        if infinite_at(cell).is_some_and(|k| k != i) {
            return true;
        }
        let [a, b, c] = FACES[i].map(|l| self.points[cell[l] as usize]);
        orient3d(a, b, c, p) == Sign::Positive
    }

    /// Insert vertex `v` (not yet a vertex; not at any vertex) into the cavity grown from
    /// tetrahedron `start`, which contains it.
    pub(super) fn insert_vertex(&mut self, v: u32, start: u32) {
        let mut scratch = std::mem::take(&mut self.scratch);
        self.grow_cavity(&mut scratch, v, start);
        self.fill_cavity(&mut scratch);
        scratch.end();
        self.scratch = scratch;
    }

    /// The cavity of `v` from `start`: the tetrahedra in conflict reachable through others,
    /// and those across boundary faces that do not join `v` positively. A face between strict
    /// verdicts needs no test: the two circumspheres meet in the face's plane, so a point
    /// strictly inside one and strictly outside the other is strictly on the first's side (as
    /// long as the tetrahedralisation is Delaunay: no repair so far).
    fn grow_cavity(&mut self, s: &mut Scratch, v: u32, start: u32) {
        let p = self.points[v as usize];
        s.begin(self.cells.len());
        // A point in a tetrahedron's closure, not at a vertex, is strictly inside its sphere.
        s.judge(start, Verdict::Inside);
        while let Some(t) = s.stack.pop() {
            let strict = s.verdicts[t as usize] == Some(Verdict::Inside) && self.repairs == 0;
            for i in 0..4 {
                let n = self.cells[t as usize].neighbours[i];
                let verdict = s.verdicts[n as usize].unwrap_or_else(|| {
                    let new = self.verdict(n, p);
                    s.judge(n, new);
                    new
                });
                if verdict.inside() || (strict && verdict == Verdict::Outside) || self.joins_positive(t, i, p)
                {
                    continue;
                }
                self.repairs += 1;
                s.judge(n, Verdict::InsideByTie);
            }
        }
        for &t in &s.cavity {
            let cell = self.cells[t as usize].vertices;
            for (i, &n) in self.cells[t as usize].neighbours.iter().enumerate() {
                if s.inside(n) {
                    continue;
                }
                let back =
                    self.cells[n as usize].neighbours.iter().position(|&m| m == t).expect("linked faces");
                let mut joined = cell;
                joined[i] = v;
                s.boundary.push(BoundaryFace { cell: joined, apex: i, outside: n, back });
            }
        }
    }

    /// Replace the cavity's tetrahedra by those of its boundary faces, in the cavity's slots
    /// first, and link them.
    fn fill_cavity(&mut self, s: &mut Scratch) {
        for (k, face) in s.boundary.iter().enumerate() {
            let slot = match s.cavity.get(k) {
                Some(&slot) => slot,
                None => self.free.pop().unwrap_or_else(|| {
                    let slot = u32::try_from(self.cells.len()).ok().filter(|&t| t < FREE);
                    self.cells.push(Cell::FREE);
                    slot.expect("fewer than 2^32 - 2 tetrahedra")
                }),
            };
            self.cells[slot as usize].vertices = face.cell;
            self.cells[slot as usize].neighbours[face.apex] = face.outside;
            self.cells[face.outside as usize].neighbours[face.back] = slot;
            s.created.push(slot);
        }
        for &slot in s.cavity.iter().skip(s.boundary.len()) {
            self.cells[slot as usize].vertices = [FREE; 4];
            self.free.push(slot);
        }
        s.edges.reset(s.boundary.len());
        for (face, &slot) in s.boundary.iter().zip(&s.created) {
            for j in (0..4).filter(|&j| j != face.apex) {
                let (x, y) = after_apex(face.apex, j);
                let (a, b) = (face.cell[x], face.cell[y]);
                // The tetrahedron across reads the shared face (v, b, a).
                match s.edges.get(b, a) {
                    Some((other, l)) => {
                        self.cells[slot as usize].neighbours[j] = other;
                        self.cells[other as usize].neighbours[l] = slot;
                    }
                    None => s.edges.put(a, b, slot, j),
                }
            }
        }
        let finite = s.created.iter().rev().find(|&&t| !self.cells[t as usize].vertices.contains(&INFINITE));
        self.hint = *finite.expect("a new vertex has a finite tetrahedron");
    }
}

/// The new tetrahedra's faces through the new point waiting for their neighbour, by their
/// directed edge off the point: an open-addressing hash table cleared after each insertion.
#[derive(Clone, Debug, Default)]
struct EdgeTable {
    keys: Vec<u64>,
    values: Vec<(u32, usize)>,
    used: Vec<usize>,
}

/// An empty [`EdgeTable`] entry (no edge runs from the infinite vertex to itself).
const NO_EDGE: u64 = u64::MAX;

impl EdgeTable {
    /// Empty, with room for the faces of `tets` new tetrahedra at a load of at most 3/8.
    fn reset(&mut self, tets: usize) {
        for &i in &self.used {
            self.keys[i] = NO_EDGE;
        }
        self.used.clear();
        let size = (4 * tets).next_power_of_two().max(64);
        if size > self.keys.len() {
            self.keys = vec![NO_EDGE; size];
            self.values = vec![(0, 0); size];
        }
    }

    fn slot(&self, key: u64) -> usize {
        let bits = self.keys.len().trailing_zeros();
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - bits)) as usize
    }

    fn put(&mut self, a: u32, b: u32, tet: u32, face: usize) {
        let key = (u64::from(a) << 32) | u64::from(b);
        let mask = self.keys.len() - 1;
        let mut i = self.slot(key);
        while self.keys[i] != NO_EDGE {
            i = (i + 1) & mask;
        }
        self.keys[i] = key;
        self.values[i] = (tet, face);
        self.used.push(i);
    }

    /// The face put under edge `(a, b)`, if any (it stays in the table: each is asked once).
    fn get(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        let key = (u64::from(a) << 32) | u64::from(b);
        let mask = self.keys.len() - 1;
        let mut i = self.slot(key);
        while self.keys[i] != NO_EDGE {
            if self.keys[i] == key {
                return Some(self.values[i]);
            }
            i = (i + 1) & mask;
        }
        None
    }
}
